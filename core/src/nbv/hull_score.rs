//! [`HullScore`]: when the unseen area of an object's hull ([`HullSurface`](super::HullSurface))
//! ranks its candidates in place of eq. (4) over the object's surface.

use serde::de::{self, Deserializer, Visitor};
use serde::{Deserialize, Serialize};

/// When the unseen hull scores an object's candidates (`[nbv] hull_score` in a scene,
/// kebab-case names; with `object_surface`).
///
/// Eq. (4) counts voxels that may hold surface; the hull counts the unseen surface a view
/// would return. Eq. (4) ranks well while there is much to see and poorly once the rest lies
/// where its voxels mislead it (a bottle's far side behind the laser's shadow): it then picks
/// views that add nothing. `AfterStall` keeps eq. (4) until a view of the object adds less
/// than the new-surface share (`[nbv] new_surface`), then ranks that object's candidates by
/// the hull, whose own stop ends the object once no candidate would see the rest. In either
/// hull mode, after a stall the candidates come from the sphere at half its steps
/// ([`ViewSphere::refined`](super::ViewSphere::refined)): what is left is a strip the
/// coarse sphere sees only past the grazing cut (docs/exploration.md, "Scoring the unseen
/// hull"). `First` ranks by the hull from the first view and, when the hull's stop would
/// end the object, hands it to eq. (4) for what a convex hull cannot hold (a horse's belly
/// between its legs, a handle's inside) if the object's latest view still added surface:
/// eq. (4) keeps the object while its views add surface, and one view that adds less than
/// the new-surface share ends it ([`HullScore::hands_over`]).
///
/// ```
/// use nbv_core::nbv::HullScore;
/// assert!(!HullScore::Off.applies(true));
/// assert!(!HullScore::AfterStall.applies(false));
/// assert!(HullScore::AfterStall.applies(true));
/// assert!(HullScore::Always.applies(false));
/// assert!(HullScore::First.applies(false) && HullScore::First.hands_over());
/// assert!(!HullScore::Always.hands_over());
/// assert_eq!("after-stall".parse::<HullScore>(), Ok(HullScore::AfterStall));
/// assert!("true".parse::<HullScore>().is_err());
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum HullScore {
    /// Eq. (4) always.
    #[default]
    Off,
    /// Eq. (4) until a view of the object adds less than the new-surface share, then the
    /// hull.
    AfterStall,
    /// The hull from the first view on.
    Always,
    /// The hull from the first view on, then eq. (4) once the hull's stop would end the
    /// object.
    First,
}

impl HullScore {
    /// Whether the hull scores the next candidates of an object, given whether one of its
    /// views `stalled` (added less than the new-surface share).
    pub fn applies(self, stalled: bool) -> bool {
        match self {
            Self::Off => false,
            Self::AfterStall => stalled,
            Self::Always | Self::First => true,
        }
    }

    /// Whether eq. (4) takes the object over when the hull's stop would end it.
    pub fn hands_over(self) -> bool {
        self == Self::First
    }
}

impl std::str::FromStr for HullScore {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "off" => Ok(Self::Off),
            "after-stall" => Ok(Self::AfterStall),
            "always" => Ok(Self::Always),
            "first" => Ok(Self::First),
            _ => Err(format!("{s:?} is not {NAMES}")),
        }
    }
}

/// The names a scene may give.
const NAMES: &str = r#""off", "after-stall", "always" or "first""#;

/// From its name; any other value (a bool included) is an error that lists the names.
impl<'de> Deserialize<'de> for HullScore {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Name;
        impl Visitor<'_> for Name {
            type Value = HullScore;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(NAMES)
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<HullScore, E> {
                v.parse()
                    .map_err(|_| E::invalid_value(de::Unexpected::Str(v), &self))
            }
        }
        deserializer.deserialize_any(Name)
    }
}
