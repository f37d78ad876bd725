//! [`average_frames`]: one depth frame from several taken at the same pose — the
//! per-pixel mean of the valid returns, where enough of them are valid.
//!
//! A time-of-flight camera held still is averaged over a burst of frames to bring its
//! range noise down by `√n` (the Dinast IPA-1110 streams at 30 Hz, so eight frames cost a
//! quarter of a second while the arm stands at the viewpoint).

use super::{DepthFrame, RigError};

/// The frame whose pixels are the means of the valid depths of `frames` (NaN where at
/// most `share` of them are valid, or none), stamped with the mean exposure time. A pixel's truth
/// (when every frame carries truth) is the first frame's that has one: the pose and the
/// scene are the same for the whole burst. Every frame must have the first one's size.
///
/// ```
/// use nbv_core::rig::{DepthFrame, average_frames};
/// let frame = |time, depth: Vec<f32>| DepthFrame { time, width: 2, height: 1, depth, truth: None };
/// let burst = [
///     frame(0.0, vec![0.50, f32::NAN]),
///     frame(1.0, vec![0.52, f32::NAN]),
///     frame(2.0, vec![f32::NAN, 0.3]),
/// ];
/// let avg = average_frames(&burst, 0.5).unwrap(); // more than half
/// assert!((avg.depth[0] - 0.51).abs() < 1e-6);    // two valid of three: their mean
/// assert!(avg.depth[1].is_nan());                 // one valid of three: invalid
/// assert_eq!(avg.time, 1.0);
/// assert_eq!(average_frames(&burst, 0.2).unwrap().depth[1], 0.3); // more than a fifth
/// ```
pub fn average_frames(frames: &[DepthFrame], share: f64) -> Result<DepthFrame, RigError> {
    let Some(first) = frames.first() else {
        return Err(RigError::State {
            device: "depth camera".into(),
            detail: "no frame to average".into(),
        });
    };
    if let Some(f) = frames.iter().find(|f| {
        (f.width, f.height, f.depth.len()) != (first.width, first.height, first.depth.len())
    }) {
        return Err(RigError::Protocol {
            device: "depth camera".into(),
            detail: format!(
                "frames of different sizes in one burst: {}x{} and {}x{}",
                first.width, first.height, f.width, f.height
            ),
        });
    }
    let n = frames.len();
    let depth = (0..first.depth.len())
        .map(|i| {
            let (sum, valid) = frames
                .iter()
                .map(|f| f64::from(f.depth[i]))
                .filter(|d| d.is_finite())
                .fold((0.0, 0usize), |(s, c), d| (s + d, c + 1));
            if valid > 0 && valid as f64 > share * n as f64 {
                (sum / valid as f64) as f32
            } else {
                f32::NAN
            }
        })
        .collect();
    Ok(DepthFrame {
        time: frames.iter().map(|f| f.time).sum::<f64>() / n as f64,
        width: first.width,
        height: first.height,
        depth,
        truth: burst_truth(frames),
    })
}

/// Per pixel, the first truth of the burst; `None` unless every frame carries truth.
fn burst_truth(frames: &[DepthFrame]) -> Option<Vec<Option<super::TruthHit>>> {
    let all: Vec<&Vec<Option<super::TruthHit>>> = frames
        .iter()
        .map(|f| f.truth.as_ref())
        .collect::<Option<_>>()?;
    let first = all.first()?;
    Some(
        (0..first.len())
            .map(|i| all.iter().find_map(|t| t.get(i).copied().flatten()))
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn frame(depth: Vec<f32>) -> DepthFrame {
        DepthFrame {
            time: 0.0,
            width: depth.len(),
            height: 1,
            depth,
            truth: None,
        }
    }

    proptest! {
        /// Each pixel of the average lies between the smallest and largest valid depth of
        /// the burst, and is valid exactly when more than `share` of the burst is.
        #[test]
        fn the_mean_lies_within_the_valid_depths(
            burst in prop::collection::vec(prop::collection::vec(prop::option::of(0.1f32..0.8), 4), 1..9),
            share in prop::sample::select(vec![0.0, 0.2, 0.5, 0.9]),
        ) {
            let frames: Vec<DepthFrame> = burst
                .iter()
                .map(|f| frame(f.iter().map(|d| d.unwrap_or(f32::NAN)).collect()))
                .collect();
            let avg = average_frames(&frames, share).unwrap();
            for (i, &d) in avg.depth.iter().enumerate() {
                let valid: Vec<f32> = burst.iter().filter_map(|f| f[i]).collect();
                let kept = !valid.is_empty() && valid.len() as f64 > share * burst.len() as f64;
                prop_assert_eq!(d.is_finite(), kept);
                if d.is_finite() {
                    let lo = valid.iter().copied().fold(f32::INFINITY, f32::min);
                    let hi = valid.iter().copied().fold(f32::NEG_INFINITY, f32::max);
                    prop_assert!(d >= lo - 1e-6 && d <= hi + 1e-6);
                }
            }
        }
    }

    #[test]
    fn bursts_of_mixed_sizes_and_empty_bursts_are_errors() {
        assert!(average_frames(&[], 0.5).is_err());
        let e = average_frames(&[frame(vec![0.5; 2]), frame(vec![0.5; 3])], 0.5).unwrap_err();
        assert!(e.to_string().contains("different sizes"), "{e}");
    }
}
