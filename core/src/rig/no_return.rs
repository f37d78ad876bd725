//! [`no_return_pixels`]: the pixels of a burst of depth frames that returned nothing, away
//! from any that did — what a depth camera says about space where it sees no surface.

use super::DepthFrame;

/// The pixels without a return in any frame of `frames` whose eight neighbours (those
/// inside the image) returned nothing in any frame either; row-major, one per pixel.
/// Empty if `frames` is empty or their sizes differ.
///
/// A pixel that stays empty through a whole burst saw no surface within the camera's
/// range, or one it cannot return from (a grazing or dark surface). The second kind lies
/// at the edge of what the camera does see; the neighbour rule keeps the image's
/// silhouettes out.
///
/// ```
/// use nbv_core::rig::{DepthFrame, no_return_pixels};
/// let mut depth = vec![f32::NAN; 4 * 3];
/// depth[0] = 0.5; // one return, in the top-left corner
/// let frame = DepthFrame { time: 0.0, width: 4, height: 3, depth, truth: None };
/// let mask = no_return_pixels(&[frame]);
/// // The return and its neighbours are out.
/// let (f, t) = (false, true);
/// assert_eq!(mask, [f, f, t, t, f, f, t, t, t, t, t, t]);
/// ```
pub fn no_return_pixels(frames: &[DepthFrame]) -> Vec<bool> {
    let Some(first) = frames.first() else {
        return Vec::new();
    };
    let (w, h) = (first.width, first.height);
    let n = w * h;
    if frames
        .iter()
        .any(|f| f.width != w || f.height != h || f.depth.len() != n)
    {
        return Vec::new();
    }
    let empty: Vec<bool> = (0..n)
        .map(|i| frames.iter().all(|f| !f.depth[i].is_finite()))
        .collect();
    (0..n)
        .map(|i| {
            let (u, v) = (i % w, i / w);
            let rows = v.saturating_sub(1)..=(v + 1).min(h - 1);
            rows.into_iter()
                .all(|r| (u.saturating_sub(1)..=(u + 1).min(w - 1)).all(|c| empty[r * w + c]))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(width: usize, height: usize, returns: &[usize]) -> DepthFrame {
        let mut depth = vec![f32::NAN; width * height];
        for &i in returns {
            depth[i] = 0.4;
        }
        DepthFrame {
            time: 0.0,
            width,
            height,
            depth,
            truth: None,
        }
    }

    #[test]
    fn one_return_in_a_burst_keeps_the_pixel_and_its_neighbours() {
        // A 5x5 image; the centre returned in the third frame of four only.
        let burst = [
            frame(5, 5, &[]),
            frame(5, 5, &[]),
            frame(5, 5, &[12]),
            frame(5, 5, &[]),
        ];
        let mask = no_return_pixels(&burst);
        let kept: Vec<usize> = (0..25).filter(|&i| !mask[i]).collect();
        assert_eq!(kept, vec![6, 7, 8, 11, 12, 13, 16, 17, 18]);
        // Nothing returned at all: every pixel, borders included.
        assert!(no_return_pixels(&burst[..2]).iter().all(|&e| e));
        // No frame, or frames of different sizes: no pixel.
        assert!(no_return_pixels(&[]).is_empty());
        assert!(no_return_pixels(&[frame(5, 5, &[]), frame(4, 5, &[])]).is_empty());
    }
}
