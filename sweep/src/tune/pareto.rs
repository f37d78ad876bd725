//! The non-dominated trials of losses (every objective to be made small), the hypervolume
//! they dominate (two objectives), and the knee of a front.

/// Whether `a` dominates `b`: no worse in every loss and better in one.
pub fn dominates(a: &[f64], b: &[f64]) -> bool {
    a.iter().zip(b).all(|(x, y)| x <= y) && a.iter().zip(b).any(|(x, y)| x < y)
}

/// The indices of the points no other point dominates, in input order (of equal points,
/// the first).
pub fn front(points: &[Vec<f64>]) -> Vec<usize> {
    (0..points.len())
        .filter(|&i| {
            !points
                .iter()
                .enumerate()
                .any(|(j, p)| dominates(p, &points[i]) || (j < i && *p == points[i]))
        })
        .collect()
}

/// The area two-objective `points` dominate up to `reference` (points beyond it count
/// for nothing).
pub fn hypervolume(points: &[Vec<f64>], reference: [f64; 2]) -> f64 {
    let mut f: Vec<[f64; 2]> = front(points)
        .into_iter()
        .map(|i| [points[i][0], points[i][1]])
        .filter(|p| p[0] < reference[0] && p[1] < reference[1])
        .collect();
    f.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let mut area = 0.0;
    let mut ceiling = reference[1];
    for p in f {
        area += (reference[0] - p[0]) * (ceiling - p[1]).max(0.0);
        ceiling = ceiling.min(p[1]);
    }
    area
}

/// The front point nearest the ideal point (each loss's best on the front), the losses
/// scaled by the front's range: the balanced choice.
pub fn knee(points: &[Vec<f64>], front: &[usize]) -> Option<usize> {
    let d = points.first()?.len();
    let lo: Vec<f64> = (0..d)
        .map(|k| {
            front
                .iter()
                .map(|&i| points[i][k])
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    let hi: Vec<f64> = (0..d)
        .map(|k| {
            front
                .iter()
                .map(|&i| points[i][k])
                .fold(f64::NEG_INFINITY, f64::max)
        })
        .collect();
    let distance = |i: usize| -> f64 {
        (0..d)
            .map(|k| {
                let range = (hi[k] - lo[k]).max(1e-12);
                ((points[i][k] - lo[k]) / range).powi(2)
            })
            .sum()
    };
    front
        .iter()
        .copied()
        .min_by(|&a, &b| distance(a).total_cmp(&distance(b)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn a_hand_made_front() {
        let p = vec![
            vec![1.0, 4.0],
            vec![2.0, 2.0],
            vec![3.0, 3.0], // dominated by (2, 2)
            vec![4.0, 1.0],
            vec![2.0, 2.0], // a repeat
        ];
        assert_eq!(front(&p), [0, 1, 3]);
        // Up to (5, 5): 1x4 + ... = staircase (1,4),(2,2),(4,1): 4*1 + 3*2 + 1*1 = 11.
        assert!((hypervolume(&p, [5.0, 5.0]) - 11.0).abs() < 1e-12);
        assert_eq!(knee(&p, &front(&p)), Some(1));
    }

    proptest! {
        /// No front point is dominated, every other point is dominated by (or equal to) a
        /// front point, and adding a point never lowers the hypervolume.
        #[test]
        fn the_front_is_exactly_the_non_dominated(
            pts in prop::collection::vec(prop::array::uniform2(0.0f64..10.0), 1..30),
            extra in prop::array::uniform2(0.0f64..10.0),
        ) {
            let p: Vec<Vec<f64>> = pts.iter().map(|a| a.to_vec()).collect();
            let f = front(&p);
            for &i in &f {
                prop_assert!(!p.iter().any(|q| dominates(q, &p[i])));
            }
            for i in (0..p.len()).filter(|i| !f.contains(i)) {
                prop_assert!(f.iter().any(|&j| dominates(&p[j], &p[i]) || p[j] == p[i]));
            }
            let hv = hypervolume(&p, [10.0, 10.0]);
            let mut more = p.clone();
            more.push(extra.to_vec());
            prop_assert!(hypervolume(&more, [10.0, 10.0]) >= hv - 1e-9);
        }
    }
}
