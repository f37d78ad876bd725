//! Post-processing of a joint-space polyline: length, random shortcutting and resampling.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::kinematics::Joints;

/// Consecutive waypoints closer than this (rad) are merged.
const DUPLICATE: f64 = 1e-12;

/// Joint-space length (sum of Euclidean segment lengths, rad).
pub fn path_length(path: &[Joints]) -> f64 {
    path.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// The point at arc length `s` and the index of the segment it lies on.
fn point_at(path: &[Joints], s: f64) -> (usize, Joints) {
    let mut left = s;
    for (i, w) in path.windows(2).enumerate() {
        let len = (w[1] - w[0]).norm();
        if left <= len || i + 2 == path.len() {
            let f = if len > 0.0 {
                (left / len).clamp(0.0, 1.0)
            } else {
                0.0
            };
            return (i, w[0] + (w[1] - w[0]) * f);
        }
        left -= len;
    }
    (0, path[0])
}

/// Drops consecutive duplicates (the first and last waypoints are kept).
pub(crate) fn dedup(path: &mut Vec<Joints>) {
    if path.len() < 2 {
        return;
    }
    let last = path[path.len() - 1];
    path.dedup_by(|b, a| (*b - *a).norm() < DUPLICATE);
    if let Some(end) = path.last_mut() {
        *end = last;
    }
    if path.len() == 1 {
        path.push(last);
    }
}

/// Random shortcutting: `iterations` times, pick two arc-length positions uniformly on the
/// path; if they lie on different segments and the straight segment between the two points
/// is free (`free`), splice it in place of the path between them. Endpoints never change.
/// Returns the number of shortcuts applied.
pub(crate) fn shortcut(
    path: &mut Vec<Joints>,
    iterations: usize,
    rng: &mut ChaCha8Rng,
    mut free: impl FnMut(&Joints, &Joints) -> bool,
) -> usize {
    let mut applied = 0;
    for _ in 0..iterations {
        if path.len() < 3 {
            break;
        }
        let total = path_length(path);
        if total <= 0.0 {
            break;
        }
        let (a, b) = (rng.random_range(0.0..total), rng.random_range(0.0..total));
        let (s1, s2) = if a <= b { (a, b) } else { (b, a) };
        let (i1, p1) = point_at(path, s1);
        let (i2, p2) = point_at(path, s2);
        if i1 == i2 {
            continue;
        }
        // The replacement must be shorter than what it replaces.
        let old =
            (path[i1 + 1] - p1).norm() + path_length(&path[i1 + 1..=i2]) + (p2 - path[i2]).norm();
        if (p2 - p1).norm() >= old - DUPLICATE {
            continue;
        }
        if free(&p1, &p2) {
            let mut next = Vec::with_capacity(path.len());
            next.extend_from_slice(&path[..=i1]);
            next.push(p1);
            next.push(p2);
            next.extend_from_slice(&path[i2 + 1..]);
            dedup(&mut next);
            *path = next;
            applied += 1;
        }
    }
    applied
}

/// Resamples every segment into equal pieces of at most `max_step` (rad).
pub(crate) fn interpolate(path: &[Joints], max_step: f64) -> Vec<Joints> {
    let mut out = Vec::with_capacity(path.len());
    if let Some(first) = path.first() {
        out.push(*first);
    }
    for w in path.windows(2) {
        let n = ((w[1] - w[0]).norm() / max_step).ceil().max(1.0) as usize;
        for i in 1..=n {
            out.push(w[0] + (w[1] - w[0]) * (i as f64 / n as f64));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn j(x: f64, y: f64) -> Joints {
        Joints::new(x, y, 0.0, 0.0, 0.0, 0.0)
    }

    #[test]
    fn length_point_and_interpolation() {
        let p = vec![j(0.0, 0.0), j(3.0, 0.0), j(3.0, 4.0)];
        assert!((path_length(&p) - 7.0).abs() < 1e-15);
        assert_eq!(point_at(&p, 1.0), (0, j(1.0, 0.0)));
        assert_eq!(point_at(&p, 5.0), (1, j(3.0, 2.0)));
        assert_eq!(point_at(&p, 7.0).1, j(3.0, 4.0));
        let q = interpolate(&p, 1.0);
        assert_eq!(q.len(), 8);
        assert_eq!(q[3], j(3.0, 0.0));
        assert!(q.windows(2).all(|w| (w[1] - w[0]).norm() <= 1.0 + 1e-12));
        assert!((path_length(&q) - 7.0).abs() < 1e-12);
    }

    #[test]
    fn shortcut_straightens_a_free_detour_and_keeps_a_blocked_one() {
        // A detour around (1, 0): free space everywhere → straight line at the end.
        let p = vec![j(0.0, 0.0), j(0.0, 1.0), j(2.0, 1.0), j(2.0, 0.0)];
        let mut free = p.clone();
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let n = shortcut(&mut free, 200, &mut rng, |_, _| true);
        assert!(n > 0);
        assert_eq!(free.first(), p.first());
        assert_eq!(free.last(), p.last());
        assert!(path_length(&free) < 2.2, "{}", path_length(&free));
        // Nothing may cut below y = 0.5: the path stays at least as long as 2 + 2·0.5.
        let mut blocked = p.clone();
        let below = |a: &Joints, b: &Joints| {
            (0..=100).all(|i| (a + (b - a) * (i as f64 / 100.0))[1] >= 0.5 - 1e-9)
                || (a[1] < 0.5 && b[1] < 0.5 && (a[0] - b[0]).abs() < 1e-12)
        };
        shortcut(&mut blocked, 200, &mut rng, below);
        assert!(path_length(&blocked) >= 2.0 + 1.0 - 1e-9);
        assert!(path_length(&blocked) <= path_length(&p));
    }

    #[test]
    fn dedup_keeps_endpoints() {
        let mut p = vec![j(0.0, 0.0), j(0.0, 0.0), j(1.0, 0.0), j(1.0, 0.0)];
        dedup(&mut p);
        assert_eq!(p, vec![j(0.0, 0.0), j(1.0, 0.0)]);
        let mut p = vec![j(0.0, 0.0), j(0.0, 0.0)];
        dedup(&mut p);
        assert_eq!(p.len(), 2);
    }
}
