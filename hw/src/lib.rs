//! # nbv-hw
//!
//! Drivers for the real rig, one cargo feature per device (`lms400`, `comau`, `dinast`;
//! `hw` enables all three). The drivers implement the same rig traits as the twin, so the
//! pipeline runs unchanged on either. No driver is implemented yet.
