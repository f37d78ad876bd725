//! Non-finite points (PCL's NaN pixels of organised clouds, failed normals):
//! [`PointCloud::drop_non_finite`] and the readers' [`NonFinite`] policy.

use super::error::{CloudIoError, CloudIoErrorKind, Location};
use super::options::{CloudFile, NonFinite};
use crate::cloud::PointCloud;

fn finite3(v: [f64; 3]) -> bool {
    v.iter().all(|c| c.is_finite())
}

/// The first point whose position, origin or normal has a NaN or infinite coordinate, and
/// the name of that column.
fn first_non_finite(cloud: &PointCloud) -> Option<(usize, &'static str)> {
    (0..cloud.len()).find_map(|i| point_fault(cloud, i).map(|c| (i, c)))
}

fn point_fault(cloud: &PointCloud, i: usize) -> Option<&'static str> {
    let p = cloud.points.get(i)?;
    if !finite3([p.x, p.y, p.z]) {
        return Some("point");
    }
    if let Some(o) = cloud.origins.as_ref().and_then(|o| o.get(i))
        && !finite3([o.x, o.y, o.z])
    {
        return Some("origin");
    }
    if let Some(n) = cloud.normals.as_ref().and_then(|n| n.get(i))
        && !finite3([n.x, n.y, n.z])
    {
        return Some("normal");
    }
    None
}

impl PointCloud {
    /// Removes the points whose position, origin or normal has a NaN or infinite
    /// coordinate (the columns [`PointCloud::validate`] checks), keeping every column in
    /// step, and returns how many were removed. `truth` is not inspected.
    ///
    /// ```
    /// use nbv_core::cloud::PointCloud;
    /// use nalgebra::Point3;
    /// let mut c = PointCloud::from_points(vec![Point3::new(0.0, 0.0, 1.0), Point3::new(f64::NAN, 0.0, 0.0)]);
    /// c.labels = Some(vec![4, 5]);
    /// assert_eq!(c.drop_non_finite(), 1);
    /// assert_eq!(c.labels, Some(vec![4]));
    /// ```
    pub fn drop_non_finite(&mut self) -> usize {
        if first_non_finite(self).is_none() {
            return 0;
        }
        let keep: Vec<bool> = (0..self.len())
            .map(|i| point_fault(self, i).is_none())
            .collect();
        fn retain<T>(col: &mut Vec<T>, keep: &[bool]) {
            let mut i = 0;
            col.retain(|_| {
                i += 1;
                keep.get(i - 1).copied().unwrap_or(true)
            });
        }
        retain(&mut self.points, &keep);
        for col in [&mut self.origins, &mut self.truth].into_iter().flatten() {
            retain(col, &keep);
        }
        if let Some(c) = &mut self.normals {
            retain(c, &keep);
        }
        for col in [&mut self.labels, &mut self.views].into_iter().flatten() {
            retain(col, &keep);
        }
        keep.iter().filter(|&&k| !k).count()
    }
}

/// Applies a reader's non-finite policy to a freshly read file.
pub(crate) fn apply_policy(file: &mut CloudFile, policy: NonFinite) -> Result<(), CloudIoError> {
    match policy {
        NonFinite::Keep => Ok(()),
        NonFinite::Drop => {
            file.dropped_non_finite = file.cloud.drop_non_finite();
            Ok(())
        }
        NonFinite::Reject => match first_non_finite(&file.cloud) {
            Some((i, column)) => Err(CloudIoError::at(
                Location::Point(i),
                CloudIoErrorKind::NonFinite { column },
            )),
            None => Ok(()),
        },
    }
}
