//! Registration parameters: the method switch ([`Method`]), the independent-set rule of
//! p-ICP-GPA ([`SetRule`]), and the parameter sets ([`RegistrationParams`] for multi-view
//! registration, [`IcpParams`] for one pair).

use serde::{Deserialize, Serialize};

use super::RegistrationError;

/// Which multi-view registration algorithm [`register`](super::register) runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// p-ICP-GPA: every view registered simultaneously against the centroids of the
    /// independent sets (paper, Figure 4).
    Gpa,
    /// The baseline: view h registered onto view h−1 by pairwise ICP, chained outward from
    /// the reference view, so pairwise errors accumulate along the chain.
    SequentialIcp {
        /// Point-to-plane instead of point-to-point error.
        point_to_plane: bool,
    },
}

/// How p-ICP-GPA turns the mutual-nearest-neighbour graph into independent sets.
///
/// The graph has one node per point and an edge between two points of different views
/// that are mutual nearest neighbours within `d_max`. A point has at most one mutual
/// nearest neighbour per other view, so a complete subgraph never holds two points of
/// one view.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SetRule {
    /// The paper's definition: a set is a connected component that is a complete graph
    /// (every member is the mutual nearest neighbour of every other). Components that are
    /// not complete are dropped whole, so no point is in two sets.
    #[default]
    Cliques,
    /// The rule of a public implementation: every connected component that has at most
    /// one point per view, complete or not. Components with two points of a view are
    /// dropped.
    Components,
}

/// Parameters of multi-view registration ([`register`](super::register)).
///
/// ```
/// use nbv_core::registration::{Method, RegistrationParams};
/// let p = RegistrationParams { method: Method::SequentialIcp { point_to_plane: true },
///                              ..RegistrationParams::default() };
/// assert!(p.validate().is_ok());
/// assert!(p.icp_params(true).point_to_plane);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RegistrationParams {
    /// The algorithm.
    pub method: Method,
    /// Index of the reference view: its output pose is its initial pose, every other pose
    /// is expressed relative to it (the paper uses the mid-range view).
    pub reference: usize,
    /// `d_max`: correspondences farther apart than this are not used (metres).
    pub max_correspondence_distance: f64,
    /// Cap on outer iterations (for sequential ICP: per pair).
    pub max_iterations: usize,
    /// p-ICP-GPA: cap on the Procrustes fits of the generalised-Procrustes loop run on the
    /// fixed correspondences of each outer iteration (1: a single fit).
    pub max_inner_iterations: usize,
    /// Convergence: stop when the relative change of the mean squared residual between
    /// two successive iterations is at most this.
    pub tolerance: f64,
    /// p-ICP-GPA: also stop when an outer iteration would turn no view, relative to the
    /// reference view, by more than this (radians)…
    pub rotation_tolerance: f64,
    /// …and move no view's point centroid, relative to the reference view, by more than
    /// this (metres). Both 0 turn this criterion off.
    pub translation_tolerance: f64,
    /// Independent-set rule of p-ICP-GPA.
    pub set_rule: SetRule,
    /// Neighbours used to estimate normals by PCA for point-to-plane ICP when a target
    /// view carries none.
    pub normal_neighbours: usize,
}

impl Default for RegistrationParams {
    fn default() -> Self {
        Self {
            method: Method::Gpa,
            reference: 0,
            max_correspondence_distance: 0.05,
            max_iterations: 100,
            max_inner_iterations: 50,
            tolerance: 1e-6,
            rotation_tolerance: 1e-5,
            translation_tolerance: 1e-6,
            set_rule: SetRule::Cliques,
            normal_neighbours: 10,
        }
    }
}

impl RegistrationParams {
    /// Checks every value (the reference index is checked against the views later).
    pub fn validate(&self) -> Result<(), RegistrationError> {
        if self.max_inner_iterations == 0 {
            return Err(RegistrationError::InvalidParameter {
                name: "max_inner_iterations",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        for (name, value) in [
            ("rotation_tolerance", self.rotation_tolerance),
            ("translation_tolerance", self.translation_tolerance),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(RegistrationError::InvalidParameter {
                    name,
                    value,
                    reason: "must be finite and >= 0",
                });
            }
        }
        self.icp_params(false).validate()
    }

    /// The pairwise ICP parameters these stand for.
    pub fn icp_params(&self, point_to_plane: bool) -> IcpParams {
        IcpParams {
            max_correspondence_distance: self.max_correspondence_distance,
            max_iterations: self.max_iterations,
            tolerance: self.tolerance,
            point_to_plane,
            normal_neighbours: self.normal_neighbours,
        }
    }
}

/// Parameters of pairwise ICP ([`align`](super::align)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IcpParams {
    /// `d_max`: pairs farther apart than this are rejected (metres).
    pub max_correspondence_distance: f64,
    /// Cap on iterations.
    pub max_iterations: usize,
    /// Convergence: relative change of the minimised mean squared error at most this.
    pub tolerance: f64,
    /// Point-to-plane error (linearised, 6×6 solve) instead of point-to-point (SVD).
    pub point_to_plane: bool,
    /// Neighbours for PCA normals of the target when it carries none.
    pub normal_neighbours: usize,
}

impl Default for IcpParams {
    fn default() -> Self {
        RegistrationParams::default().icp_params(false)
    }
}

impl IcpParams {
    /// Checks every value.
    pub fn validate(&self) -> Result<(), RegistrationError> {
        let d = self.max_correspondence_distance;
        if !(d.is_finite() && d > 0.0) {
            return Err(RegistrationError::InvalidParameter {
                name: "max_correspondence_distance",
                value: d,
                reason: "must be finite and > 0",
            });
        }
        if self.max_iterations == 0 {
            return Err(RegistrationError::InvalidParameter {
                name: "max_iterations",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        if !(self.tolerance.is_finite() && self.tolerance >= 0.0) {
            return Err(RegistrationError::InvalidParameter {
                name: "tolerance",
                value: self.tolerance,
                reason: "must be finite and >= 0",
            });
        }
        if self.normal_neighbours < 3 {
            return Err(RegistrationError::InvalidParameter {
                name: "normal_neighbours",
                value: self.normal_neighbours as f64,
                reason: "must be at least 3",
            });
        }
        Ok(())
    }
}
