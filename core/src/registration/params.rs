//! Registration parameters: the method switch ([`Method`]), the independent-set rule of
//! p-ICP-GPA ([`SetRule`]), and the parameter sets ([`RegistrationParams`] for multi-view
//! registration, [`IcpParams`] for one pair).

use serde::{Deserialize, Serialize};

use super::RegistrationError;

/// Which multi-view registration algorithm [`register`](super::register) runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Maximum a posteriori estimate of every pose: the data weighted by each sensor's
    /// noise, a prior per view towards its reported pose, the reference view fixed
    /// ([`MapParams`]). The pipeline's default.
    Map,
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
    /// `d_max`: correspondences farther apart than this are not used (metres). Default
    /// 0.03: about twice the short-range camera's noise at working distance.
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
    /// The MAP method's own parameters.
    pub map: MapParams,
}

/// Parameters of the MAP registration ([`Method::Map`]).
///
/// ```
/// use nbv_core::registration::MapParams;
/// let p = MapParams::default();
/// assert!((p.gate_chi2 - 22.458).abs() < 1e-3); // χ²(6) at 0.999
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MapParams {
    /// Scale `c` of the Cauchy kernel, in σ of each residual (2.385: 95 % efficiency on
    /// Gaussian noise).
    pub kernel_scale: f64,
    /// Residuals beyond this many σ are outliers (constant cost, no pull).
    pub outlier_sigmas: f64,
    /// A point takes part in a stage when matched within this many σ at the stage's start
    /// (see `max_stages`).
    pub match_sigmas: f64,
    /// Stages: each fixes which points take part (those matched at its start), then
    /// minimises; the next starts where it ended, until the poses stop moving.
    pub max_stages: usize,
    /// σ added to every residual (m): what no sensor model explains (sampling, shape).
    pub floor_sigma: f64,
    /// Convergence: a step, at whatever damping, turns no view by more than this (rad)…
    pub rotation_tolerance: f64,
    /// …and moves no view's centroid by more than this (m).
    pub translation_tolerance: f64,
    /// Cap on accepted steps (a safety net; convergence is the usual exit).
    pub max_iterations: usize,
    /// χ² (6 degrees of freedom) a view's correction may reach under its prior; beyond,
    /// the view keeps its reported pose.
    pub gate_chi2: f64,
    /// Terms between non-reference views too (both ways, half weight each), not only
    /// each view into the reference. Default true: views registered among themselves
    /// (`nbv register`) need them where a view does not overlap the reference. The
    /// pipeline turns them off: its camera views go into the laser cluster alone, since at
    /// the camera's centimetre noise view-to-view terms pull registrations off (on the
    /// paper scenes' objects they leave 4–5 mm where the views into the laser cluster
    /// alone leave 1.3–2.3 mm).
    pub view_to_view: bool,
    /// Points per view used in each view-to-view term (all points into the reference).
    pub pair_points: usize,
    /// Neighbours of each point's surface element (mean and normal).
    pub surface_neighbours: usize,
    /// Match each point where its viewing ray crosses the target's surface rather than to
    /// the nearest target point (projective association): a camera point displaced along
    /// its ray by the noise finds, on a curved target, a nearest point whose plane tilts
    /// towards it, and the view settles short of the truth. Nearest points capture a view
    /// from farther off, so a run matching along the rays should start near its solution:
    /// the pipeline refines each object's final registration this way, started where it
    /// ended ([`register_prepared_from`](super::register_prepared_from)). Default false.
    pub along_rays: bool,
}

impl Default for MapParams {
    fn default() -> Self {
        Self {
            kernel_scale: 2.385,
            outlier_sigmas: 8.0,
            match_sigmas: 3.0,
            max_stages: 4,
            floor_sigma: 0.0005,
            rotation_tolerance: 0.005f64.to_radians(),
            translation_tolerance: 5e-5,
            max_iterations: 100,
            gate_chi2: 22.458,
            view_to_view: true,
            pair_points: 600,
            surface_neighbours: 16,
            along_rays: false,
        }
    }
}

impl MapParams {
    /// Checks every value.
    pub fn validate(&self) -> Result<(), RegistrationError> {
        for (name, value) in [
            ("map.kernel_scale", self.kernel_scale),
            ("map.outlier_sigmas", self.outlier_sigmas),
            ("map.match_sigmas", self.match_sigmas),
            ("map.gate_chi2", self.gate_chi2),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(RegistrationError::InvalidParameter {
                    name,
                    value,
                    reason: "must be finite and > 0",
                });
            }
        }
        for (name, value) in [
            ("map.floor_sigma", self.floor_sigma),
            ("map.rotation_tolerance", self.rotation_tolerance),
            ("map.translation_tolerance", self.translation_tolerance),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(RegistrationError::InvalidParameter {
                    name,
                    value,
                    reason: "must be finite and >= 0",
                });
            }
        }
        for (name, value) in [
            ("map.max_iterations", self.max_iterations),
            ("map.max_stages", self.max_stages),
            ("map.pair_points", self.pair_points),
            (
                "map.surface_neighbours",
                self.surface_neighbours.saturating_sub(2),
            ),
        ] {
            if value == 0 {
                return Err(RegistrationError::InvalidParameter {
                    name,
                    value: value as f64,
                    reason: "must be at least 1 (surface_neighbours: at least 3)",
                });
            }
        }
        Ok(())
    }
}

impl Default for RegistrationParams {
    fn default() -> Self {
        Self {
            method: Method::Gpa,
            reference: 0,
            max_correspondence_distance: 0.03,
            max_iterations: 100,
            max_inner_iterations: 50,
            tolerance: 1e-6,
            rotation_tolerance: 1e-5,
            translation_tolerance: 1e-6,
            set_rule: SetRule::Cliques,
            normal_neighbours: 10,
            map: MapParams::default(),
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
        self.map.validate()?;
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
