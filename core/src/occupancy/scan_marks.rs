//! [`ScanMarks`]: one mark per voxel for the scan being applied (untouched, passed, hit),
//! kept all-untouched between scans, with the lists of the voxels a scan marked — so that
//! applying a scan and clearing its marks costs the voxels it touched, never the grid.

use std::sync::atomic::{AtomicU8, Ordering};

/// The mark of a voxel no ray of the scan reached.
pub(crate) const MARK_NONE: u8 = 0;
/// The mark of a voxel crossed by a ray of the scan.
pub(crate) const MARK_FREE: u8 = 1;
/// The mark of a voxel holding a ray's end point; it overwrites [`MARK_FREE`].
pub(crate) const MARK_HIT: u8 = 2;

/// Voxel marks shared by the threads tracing one scan.
///
/// Tracing happens in two phases separated by a join (every pass, then every hit), and in
/// each phase a mark only ever changes to that phase's one value, so the marks at the end
/// do not depend on the order of rays or threads. A thread that finds a voxel untouched
/// appends it to its own list of touched voxels; two threads racing on the same voxel may
/// both append it, which [`ScanMarks::take`] absorbs (the second take finds it untouched).
/// After a scan has been applied, every touched voxel has been taken, so all marks are
/// untouched again.
#[derive(Default)]
pub(crate) struct ScanMarks {
    marks: Vec<AtomicU8>,
}

impl ScanMarks {
    /// `len` untouched marks.
    pub(crate) fn new(len: usize) -> Self {
        Self {
            marks: std::iter::repeat_with(|| AtomicU8::new(MARK_NONE))
                .take(len)
                .collect(),
        }
    }

    /// Makes room for `len` voxels (only the first call allocates; marks stay untouched).
    pub(crate) fn ensure_len(&mut self, len: usize) {
        if self.marks.len() != len {
            *self = Self::new(len);
        }
    }

    /// Marks voxel `linear` passed unless it is marked already; records it in `touched`
    /// when this call found it untouched.
    #[inline]
    pub(crate) fn pass(&self, linear: usize, touched: &mut Vec<u32>) {
        let m = &self.marks[linear];
        if m.load(Ordering::Relaxed) == MARK_NONE {
            m.store(MARK_FREE, Ordering::Relaxed);
            touched.push(linear as u32);
        }
    }

    /// Marks voxel `linear` hit; records it in `touched` when it was untouched.
    #[inline]
    pub(crate) fn hit(&self, linear: usize, touched: &mut Vec<u32>) {
        let m = &self.marks[linear];
        let old = m.load(Ordering::Relaxed);
        if old == MARK_NONE {
            touched.push(linear as u32);
        }
        if old != MARK_HIT {
            m.store(MARK_HIT, Ordering::Relaxed);
        }
    }

    /// The mark of voxel `linear`, reset to untouched.
    #[inline]
    pub(crate) fn take(&mut self, linear: usize) -> u8 {
        std::mem::replace(self.marks[linear].get_mut(), MARK_NONE)
    }
}

/// A grid's marks are scratch space: a copy starts without any (its first scan allocates
/// them), so copying a grid costs its log-odds only.
impl Clone for ScanMarks {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl std::fmt::Debug for ScanMarks {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ScanMarks({} voxels)", self.marks.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marks_record_each_voxel_once_and_reset_on_take() {
        let mut m = ScanMarks::new(8);
        let mut touched = Vec::new();
        m.pass(3, &mut touched);
        m.pass(3, &mut touched);
        m.pass(5, &mut touched);
        m.hit(5, &mut touched);
        m.hit(6, &mut touched);
        m.hit(6, &mut touched);
        assert_eq!(touched, vec![3, 5, 6]);
        assert_eq!(m.take(3), MARK_FREE);
        assert_eq!(m.take(5), MARK_HIT);
        assert_eq!(m.take(6), MARK_HIT);
        assert_eq!(m.take(6), MARK_NONE);
        assert!((0..8).all(|l| m.take(l) == MARK_NONE));
        assert!(m.clone().marks.is_empty());
    }
}
