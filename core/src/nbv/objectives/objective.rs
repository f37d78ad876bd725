//! [`Objective`]: which view objective ranks the candidate viewpoints — the paper's eq. (4)
//! or one of the seven volumetric information gains of Isler et al. (ICRA 2016) and
//! Delmerico et al. (Auton. Robots 2018).

use serde::{Deserialize, Serialize};

/// The view objective (`[nbv] objective` in a scene, kebab-case names).
///
/// ```
/// use nbv_core::nbv::Objective;
/// assert_eq!(Objective::default(), Objective::Paper);
/// let o: Objective = "rear-side-entropy".parse().unwrap();
/// assert_eq!((o, o.name()), (Objective::RearSideEntropy, "rear-side-entropy"));
/// assert!("rear-side".parse::<Objective>().is_err());
/// assert_eq!(Objective::ALL.len(), 8);
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Objective {
    /// Eq. (4) of Aleotti et al.: `α_u·|O_v^u| + α_o·|O_v^o|` on the reduced map.
    #[default]
    Paper,
    /// Occlusion aware (OA): visibility-weighted entropy of every voxel on the rays.
    OcclusionAware,
    /// Unobserved voxel (UV): OA over unknown voxels only.
    UnobservedVoxel,
    /// Rear side voxel (RSV): rays entering an occupied voxel from an unknown one.
    RearSideVoxel,
    /// Rear side entropy (RSE): the unknown run before a rear-side hit.
    RearSideEntropy,
    /// Proximity count (PC): unmeasured voxels weighted by closeness behind a surface.
    ProximityCount,
    /// Area factor (AF, Vasquez-Gomez et al. 2014): target shares of surface and
    /// occlusion-plane rays.
    AreaFactor,
    /// Average entropy (AE, Kriegel et al. 2015): mean entropy on rays that hit surface.
    AverageEntropy,
}

impl Objective {
    /// Every objective, eq. (4) first.
    pub const ALL: [Objective; 8] = [
        Self::Paper,
        Self::OcclusionAware,
        Self::UnobservedVoxel,
        Self::RearSideVoxel,
        Self::RearSideEntropy,
        Self::ProximityCount,
        Self::AreaFactor,
        Self::AverageEntropy,
    ];

    /// The scene-file name.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Paper => "paper",
            Self::OcclusionAware => "occlusion-aware",
            Self::UnobservedVoxel => "unobserved-voxel",
            Self::RearSideVoxel => "rear-side-voxel",
            Self::RearSideEntropy => "rear-side-entropy",
            Self::ProximityCount => "proximity-count",
            Self::AreaFactor => "area-factor",
            Self::AverageEntropy => "average-entropy",
        }
    }

    /// Whether it needs the map's [`OcclusionDistances`](crate::occupancy::OcclusionDistances).
    pub fn needs_occlusion(&self) -> bool {
        matches!(self, Self::ProximityCount | Self::AreaFactor)
    }
}

impl std::fmt::Display for Objective {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Objective {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|o| o.name() == s)
            .ok_or_else(|| {
                let names: Vec<_> = Self::ALL.iter().map(|o| o.name()).collect();
                format!(
                    "unknown objective `{s}`, expected one of {}",
                    names.join(", ")
                )
            })
    }
}
