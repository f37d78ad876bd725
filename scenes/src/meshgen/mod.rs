//! Procedural meshes of the paper's objects (Figure 5: a jug, two plastic bottles, a
//! mallet, a toy horse and a box), at real sizes.
//!
//! Every object is a signed-distance function ([`sdf`]: lathe profiles, capsules,
//! ellipsoids, rounded boxes, joined by a smooth union) meshed by marching tetrahedra
//! ([`marching_tetrahedra`]), which gives one closed, consistently oriented surface without
//! internal faces. Object frames follow the scene convention: z up, the object rests on its
//! `z = 0` plane, centred on the origin (the body axis for lathe objects, the footprint's
//! bounding-box centre for the others).

pub mod decimate;
pub mod library;
pub mod marching_tetrahedra;
pub mod sdf;

pub use library::ObjectKind;
