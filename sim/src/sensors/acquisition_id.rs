//! [`AcquisitionId`]: which random streams an acquisition draws its noise from.

/// Identifies an acquisition for noise generation: the scene seed and the rig's
/// acquisition counter (0, 1, 2… over the rig's life: one per laser sweep, one per depth
/// frame). Equal ids give equal noise.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct AcquisitionId {
    /// The scene seed.
    pub seed: u64,
    /// The acquisition counter.
    pub index: u64,
}
