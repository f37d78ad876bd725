//! [`KNearest`]: the `k` nearest points of every point of a set, within the set — the
//! neighbourhoods that normals, surfels and neighbour graphs are fitted to — found
//! exactly by a uniform grid of cells instead of one k-d tree search per point.
//!
//! The points are sorted into cubic cells (about a quarter of `k` points per occupied
//! cell, the edge chosen from the data). The points of one cell share their candidates:
//! the points of the 3×3×3 cells around it, gathered once into columns. A point's `k`
//! nearest candidates are picked (among those within a guess taken from the previous
//! point's `k`-th distance, else among all) and are its `k` nearest points when the `k`-th
//! is nearer than every face of the block (with a margin for rounding), since every other
//! point lies beyond a face. Otherwise (about one point in seven on a depth camera's
//! views) the search grows by rings of cells. Neighbours are ranked by squared distance,
//! then by index, so the answer is one set, whatever the order of the search.

use std::num::NonZeroUsize;

use nalgebra::Point3;
use rayon::prelude::*;

use super::ProcessingError;

/// Query points per parallel work item (consecutive in cell order).
const CHUNK: usize = 512;

/// A point's search first assumes its `k`-th squared distance is at most this many times
/// the previous point's (the previous point lies in the same cell, mostly), and falls back
/// to the full search when that does not hold.
const HINT_GROWTH: f64 = 1.5;

/// The `k` nearest points of each point of a set (the point itself included, at
/// distance 0), nearest first, ties by index; fewer where the set has fewer than `k`
/// finite points. Non-finite points have no neighbours and are nobody's neighbour.
///
/// ```
/// use std::num::NonZeroUsize;
/// use nalgebra::Point3;
/// use nbv_core::cloud::KNearest;
/// let points: Vec<_> = (0..10).map(|i| Point3::new(i as f64 * 0.25, 0.0, 0.0)).collect();
/// let near = KNearest::of_each(&points, NonZeroUsize::new(3).unwrap()).unwrap();
/// let third: Vec<u32> = near.of(3).iter().map(|&(j, _)| j).collect();
/// assert_eq!(third, vec![3, 2, 4]); // itself, then the tie 2 / 4 by index
/// assert_eq!(near.of(3)[1].1, 0.0625); // squared distances
/// assert_eq!(near.of(0).len(), 3);
/// ```
#[derive(Debug, Clone)]
pub struct KNearest {
    /// Neighbours asked for per point.
    k: usize,
    /// Entries kept per point: `k`, or the set's size if smaller (no list is longer).
    stride: usize,
    /// Point i's neighbours are `entries[i * stride..i * stride + counts[i]]`.
    entries: Vec<(u32, f64)>,
    counts: Vec<u32>,
}

/// One work item's lists, in cell order: `k` entries per point, and each point's count.
type ChunkLists = (Vec<(u32, f64)>, Vec<u32>);

/// The points sorted into cubic cells.
struct CellGrid {
    lo: [f64; 3],
    edge: f64,
    dims: [usize; 3],
    /// How far (m) the `k`-th distance must stay inside the block's faces: rounding of
    /// the cell assignment and the face coordinates, with room to spare.
    margin: f64,
    /// Cell c's points are `order[start[c]..start[c + 1]]` (ascending index).
    start: Vec<u32>,
    order: Vec<u32>,
    /// The points' coordinates in `order`'s order.
    sorted: Vec<[f64; 3]>,
    /// Each point's cell (unused for non-finite points).
    cell_of: Vec<[usize; 3]>,
}

impl KNearest {
    /// The `k` nearest points of every point of `points` (in parallel; each list depends
    /// only on the data). Errors for more points than a `u32` indexes.
    pub fn of_each(points: &[Point3<f64>], k: NonZeroUsize) -> Result<Self, ProcessingError> {
        let k_asked = k.get();
        let n = points.len();
        if u32::try_from(n).is_err() {
            return Err(ProcessingError::TooManyPoints(n));
        }
        // No list is longer than the set: `k` beyond it costs nothing.
        let k = k.get().min(n.max(1));
        let mut out = Self {
            k: k_asked,
            stride: k,
            entries: vec![(0, 0.0); n * k],
            counts: vec![0; n],
        };
        let Some(grid) = CellGrid::new(points, k) else {
            return Ok(out);
        };
        let per_chunk: Vec<ChunkLists> = (0..grid.order.len().div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let range = c * CHUNK..((c + 1) * CHUNK).min(grid.order.len());
                let mut entries = Vec::with_capacity(range.len() * k);
                let mut counts = Vec::with_capacity(range.len());
                let mut best = Vec::with_capacity(k);
                let mut block = Block::default();
                let mut hint = None;
                for s in range {
                    let c = grid.cell_of[grid.order[s] as usize];
                    if block.cell != Some(c) {
                        grid.gather(c, &mut block);
                    }
                    grid.nearest(s, k, &mut hint, &mut block, &mut best);
                    counts.push(best.len() as u32);
                    entries.extend_from_slice(&best);
                    entries.resize(counts.len() * k, (0, 0.0));
                }
                (entries, counts)
            })
            .collect();
        let mut s = 0;
        for (entries, counts) in per_chunk {
            for (j, &count) in counts.iter().enumerate() {
                let i = grid.order[s] as usize;
                out.entries[i * k..(i + 1) * k].copy_from_slice(&entries[j * k..(j + 1) * k]);
                out.counts[i] = count;
                s += 1;
            }
        }
        Ok(out)
    }

    /// Neighbours per point asked for.
    pub fn k(&self) -> usize {
        self.k
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.counts.len()
    }

    /// Whether the set was empty.
    pub fn is_empty(&self) -> bool {
        self.counts.is_empty()
    }

    /// Point `i`'s nearest points as `(index, squared distance)`, nearest first, ties by
    /// index.
    pub fn of(&self, i: usize) -> &[(u32, f64)] {
        &self.entries[i * self.stride..i * self.stride + self.counts[i] as usize]
    }
}

impl CellGrid {
    /// The finite points of `points` in cells of about `k / 4` points each (None when
    /// there is no finite point).
    fn new(points: &[Point3<f64>], k: usize) -> Option<Self> {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let mut n = 0usize;
        for p in points.iter().filter(|p| finite(p)) {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
            n += 1;
        }
        if n == 0 {
            return None;
        }
        let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0f64, f64::max);
        if extent == 0.0 {
            // Every point at one place: one cell.
            return Some(Self::sorted(points, lo, hi, 1.0));
        }
        // First the edge of one point per cell were the points spread through the box,
        // then scaled to the count per occupied cell found: on a surface the count grows
        // with the edge's square.
        let volume: f64 = (0..3).map(|a| (hi[a] - lo[a]).max(extent * 1e-3)).product();
        let mut edge = (volume / n as f64).cbrt();
        let target = (k as f64 / 4.0).max(1.0);
        for _ in 0..2 {
            let (used, occupied) = Self::occupancy(points, lo, hi, edge);
            let per_cell = n as f64 / occupied.max(1) as f64;
            let scale = (target / per_cell).sqrt().clamp(0.25, 8.0);
            edge = used;
            if (0.7..1.4).contains(&scale) {
                break;
            }
            edge *= scale;
        }
        Some(Self::sorted(points, lo, hi, edge))
    }

    /// The edge (`edge`, doubled until the cell table holds at most about 8 entries per
    /// point) and the cells per axis of a grid over the box `lo`–`hi`.
    fn layout(lo: &[f64; 3], hi: &[f64; 3], edge: f64, points: usize) -> (f64, [usize; 3]) {
        let mut edge = edge;
        // Doubling from any positive f64 passes any finite extent within ~2100 steps; an
        // edge of 0 or an extent beyond f64 (coordinates near ±f64::MAX) ends in one cell.
        for _ in 0..2100 {
            let counts: [f64; 3] = std::array::from_fn(|a| ((hi[a] - lo[a]) / edge).floor() + 1.0);
            if counts.iter().product::<f64>() <= (8 * points + 64) as f64 {
                return (edge, counts.map(|c| c as usize));
            }
            edge *= 2.0;
        }
        (f64::INFINITY, [1, 1, 1])
    }

    /// The cell of finite point `p` (`p − lo ≥ 0`: the cast truncates, which is the floor).
    #[inline]
    fn cell(p: &Point3<f64>, lo: &[f64; 3], edge: f64, dims: &[usize; 3]) -> [usize; 3] {
        std::array::from_fn(|a| (((p[a] - lo[a]) / edge) as usize).min(dims[a] - 1))
    }

    /// The edge [`Self::layout`] makes of `edge`, and how many of its cells hold a point.
    fn occupancy(points: &[Point3<f64>], lo: [f64; 3], hi: [f64; 3], edge: f64) -> (f64, usize) {
        let (edge, dims) = Self::layout(&lo, &hi, edge, points.len());
        let mut seen = vec![0u64; dims.iter().product::<usize>().div_ceil(64)];
        let mut occupied = 0;
        for p in points.iter().filter(|p| finite(p)) {
            let c = Self::cell(p, &lo, edge, &dims);
            let l = c[0] + dims[0] * (c[1] + dims[1] * c[2]);
            let bit = 1u64 << (l % 64);
            occupied += usize::from(seen[l / 64] & bit == 0);
            seen[l / 64] |= bit;
        }
        (edge, occupied)
    }

    /// The finite points sorted into the cells of [`Self::layout`] of `edge` over the box
    /// `lo`–`hi`.
    fn sorted(points: &[Point3<f64>], lo: [f64; 3], hi: [f64; 3], edge: f64) -> Self {
        let (edge, dims) = Self::layout(&lo, &hi, edge, points.len());
        let cell = |p: &Point3<f64>| Self::cell(p, &lo, edge, &dims);
        let linear = |c: [usize; 3]| c[0] + dims[0] * (c[1] + dims[1] * c[2]);
        let cells = dims.iter().product::<usize>();
        let cell_of: Vec<[usize; 3]> = points.iter().map(cell).collect();
        let mut start = vec![0u32; cells + 1];
        for (p, c) in points.iter().zip(&cell_of) {
            if finite(p) {
                start[linear(*c) + 1] += 1;
            }
        }
        for c in 0..cells {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut order = vec![0u32; start[cells] as usize];
        for (i, (p, c)) in points.iter().zip(&cell_of).enumerate() {
            if finite(p) {
                let slot = &mut fill[linear(*c)];
                order[*slot as usize] = i as u32;
                *slot += 1;
            }
        }
        let sorted = order
            .iter()
            .map(|&i| {
                let p = &points[i as usize];
                [p.x, p.y, p.z]
            })
            .collect();
        let scale = (0..3)
            .map(|a| lo[a].abs().max(hi[a].abs()))
            .fold(0.0f64, f64::max);
        Self {
            lo,
            edge,
            dims,
            margin: edge * 1e-9 + scale * 1e-12,
            start,
            order,
            sorted,
            cell_of,
        }
    }

    /// The points of the 3×3×3 cells around `c` into `block`.
    fn gather(&self, c: [usize; 3], block: &mut Block) {
        block.cell = Some(c);
        block.x.clear();
        block.y.clear();
        block.z.clear();
        block.index.clear();
        let span = |a: usize| c[a].saturating_sub(1)..=(c[a] + 1).min(self.dims[a] - 1);
        for z in span(2) {
            for y in span(1) {
                // A row of the block: contiguous cells, contiguous points.
                let row = self.dims[0] * (y + self.dims[1] * z);
                let xs = span(0);
                let a = self.start[row + xs.start()] as usize;
                let b = self.start[row + xs.end() + 1] as usize;
                for p in &self.sorted[a..b] {
                    block.x.push(p[0]);
                    block.y.push(p[1]);
                    block.z.push(p[2]);
                }
                block.index.extend_from_slice(&self.order[a..b]);
            }
        }
    }

    /// The `k` nearest points of the point at sorted position `s` into `best`, nearest
    /// first, ties by index. `block` holds the points of the cells around the point's;
    /// `hint`, a guess at the `k`-th squared distance (updated for the next point), only
    /// makes the search faster when right.
    fn nearest(
        &self,
        s: usize,
        k: usize,
        hint: &mut Option<f64>,
        block: &mut Block,
        best: &mut Vec<(u32, f64)>,
    ) {
        let q = self.sorted[s];
        let c = self.cell_of[self.order[s] as usize];
        let Block {
            x,
            y,
            z,
            index,
            d2,
            keys,
            ..
        } = block;
        d2.clear();
        d2.extend(x.iter().zip(y.iter()).zip(z.iter()).map(|((px, py), pz)| {
            let (dx, dy, dz) = (px - q[0], py - q[1], pz - q[2]);
            dx * dx + dy * dy + dz * dz
        }));
        // The candidates within the hint's distance, else all of them.
        keys.clear();
        if let Some(r2) = *hint {
            keys.extend(
                d2.iter()
                    .zip(index.iter())
                    .filter(|&(&d, _)| d <= r2)
                    .map(|(&d, &i)| key(i, d)),
            );
        }
        if keys.len() < k {
            keys.clear();
            keys.extend(d2.iter().zip(index.iter()).map(|(&d, &i)| key(i, d)));
        }
        let take = k.min(keys.len());
        if take > 0 && take < keys.len() {
            keys.select_nth_unstable(take - 1);
        }
        keys.truncate(take);
        keys.sort_unstable();
        // Every point within the k-th distance lies in the block (or the block is all):
        // the k found are the nearest. Otherwise search by rings.
        let decided = self.covers_all(c, 1)
            || take == k && unkey(keys[k - 1]).1 < self.reach(&q, c, 1).powi(2);
        if !decided {
            self.by_rings(&q, c, k, keys);
        }
        best.clear();
        best.extend(keys.iter().map(|&key| unkey(key)));
        *hint = (best.len() == k).then(|| best[k - 1].1 * HINT_GROWTH);
    }

    /// The `k` nearest points of `q` (in cell `c`) into `keys`, ascending: the cells
    /// around `c` nearest first, each skipped when farther than the `k`-th point found,
    /// then rings of cells until the `k`-th point is nearer than the block's faces.
    fn by_rings(&self, q: &[f64; 3], c: [usize; 3], k: usize, keys: &mut Vec<u128>) {
        keys.clear();
        for o in NEIGHBOUR_CELLS {
            let Some((l, gap2)) = self.block_cell(q, c, o) else {
                continue;
            };
            if keys.len() == k && gap2 > (unkey(keys[k - 1]).1.sqrt() + self.margin).powi(2) {
                continue;
            }
            self.scan_points(q, self.start[l]..self.start[l + 1], k, keys);
        }
        let mut ring = 1usize;
        while !(self.covers_all(c, ring)
            || keys.len() == k && unkey(keys[k - 1]).1 < self.reach(q, c, ring).powi(2))
        {
            ring += 1;
            self.scan_ring(q, c, ring, k, keys);
        }
    }

    /// Cell `c + o` (linear index) and the squared distance from `q` (in cell `c`) to it,
    /// if it is in the grid.
    #[inline]
    fn block_cell(&self, q: &[f64; 3], c: [usize; 3], o: [isize; 3]) -> Option<(usize, f64)> {
        let mut cell = [0usize; 3];
        let mut gap2 = 0.0;
        for a in 0..3 {
            cell[a] = c[a]
                .checked_add_signed(o[a])
                .filter(|&i| i < self.dims[a])?;
            let g = match o[a] {
                -1 => q[a] - (self.lo[a] + c[a] as f64 * self.edge),
                1 => self.lo[a] + (c[a] + 1) as f64 * self.edge - q[a],
                _ => 0.0,
            };
            gap2 += g * g;
        }
        Some((
            cell[0] + self.dims[0] * (cell[1] + self.dims[1] * cell[2]),
            gap2,
        ))
    }

    /// Whether the cells within Chebyshev distance `ring` of `c` are all the grid's.
    fn covers_all(&self, c: [usize; 3], ring: usize) -> bool {
        (0..3).all(|a| c[a] <= ring && c[a] + ring + 1 >= self.dims[a])
    }

    /// How far from `q` (in cell `c`) every point outside the cells within Chebyshev
    /// distance `ring` of `c` lies at least (less the rounding margin; infinite when
    /// those cells are all the grid's, 0 or less when nothing is sure).
    fn reach(&self, q: &[f64; 3], c: [usize; 3], ring: usize) -> f64 {
        let mut face = f64::INFINITY;
        for a in 0..3 {
            if c[a] > ring {
                let plane = self.lo[a] + (c[a] - ring) as f64 * self.edge;
                face = face.min(q[a] - plane);
            }
            if c[a] + ring + 1 < self.dims[a] {
                let plane = self.lo[a] + (c[a] + ring + 1) as f64 * self.edge;
                face = face.min(plane - q[a]);
            }
        }
        (face - self.margin).max(0.0)
    }

    /// Adds the points of the cells at Chebyshev distance `ring` from cell `c` to `keys`.
    fn scan_ring(&self, q: &[f64; 3], c: [usize; 3], ring: usize, k: usize, keys: &mut Vec<u128>) {
        let span = |a: usize| c[a].saturating_sub(ring)..=(c[a] + ring).min(self.dims[a] - 1);
        for z in span(2) {
            for y in span(1) {
                let row = self.dims[0] * (y + self.dims[1] * z);
                if z.abs_diff(c[2]) == ring || y.abs_diff(c[1]) == ring {
                    // On the shell: the block's whole row (contiguous cells).
                    let xs = span(0);
                    let (first, last) = (row + xs.start(), row + xs.end());
                    self.scan_points(q, self.start[first]..self.start[last + 1], k, keys);
                } else {
                    // Inside the shell: the row's two end cells.
                    for x in [c[0].checked_sub(ring), Some(c[0] + ring)]
                        .into_iter()
                        .flatten()
                    {
                        if x < self.dims[0] {
                            let cell = row + x;
                            self.scan_points(q, self.start[cell]..self.start[cell + 1], k, keys);
                        }
                    }
                }
            }
        }
    }

    /// Adds the points at sorted positions `range` to `keys`, which keeps the `k`
    /// smallest [`key`]s, ascending.
    #[inline]
    fn scan_points(
        &self,
        q: &[f64; 3],
        range: std::ops::Range<u32>,
        k: usize,
        keys: &mut Vec<u128>,
    ) {
        let (a, b) = (range.start as usize, range.end as usize);
        for (p, &i) in self.sorted[a..b].iter().zip(&self.order[a..b]) {
            let item = key(i, squared_distance(p, q));
            if keys.len() == k {
                if item >= keys[k - 1] {
                    continue;
                }
                keys.pop();
            }
            // Insertion from the back: most new entries rank near the end.
            let mut at = keys.len();
            while at > 0 && keys[at - 1] > item {
                at -= 1;
            }
            keys.insert(at, item);
        }
    }
}

/// The offsets of a cell's 3×3×3 block, nearest first: the cell, its 6 face neighbours,
/// 12 edge neighbours and 8 corner neighbours.
const NEIGHBOUR_CELLS: [[isize; 3]; 27] = {
    let mut out = [[0isize; 3]; 27];
    let mut n = 0;
    let mut order = 0;
    while order <= 3 {
        let mut i = 0;
        while i < 27 {
            let o = [
                (i % 3) as isize - 1,
                ((i / 3) % 3) as isize - 1,
                (i / 9) as isize - 1,
            ];
            if (o[0] != 0) as usize + (o[1] != 0) as usize + (o[2] != 0) as usize == order {
                out[n] = o;
                n += 1;
            }
            i += 1;
        }
        order += 1;
    }
    out
};

/// The points of the cells around one cell, in columns, with scratch for one query.
#[derive(Default)]
struct Block {
    /// The cell whose block this is.
    cell: Option<[usize; 3]>,
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    index: Vec<u32>,
    /// Squared distances from the query.
    d2: Vec<f64>,
    /// The query's nearest, as [`key`]s.
    keys: Vec<u128>,
}

/// `|p − q|²`.
#[inline]
fn squared_distance(p: &[f64; 3], q: &[f64; 3]) -> f64 {
    let (dx, dy, dz) = (p[0] - q[0], p[1] - q[1], p[2] - q[2]);
    dx * dx + dy * dy + dz * dz
}

/// A neighbour as one integer that sorts by squared distance, then index: the bits of a
/// non-negative f64 order as the values do.
#[inline]
fn key(index: u32, d2: f64) -> u128 {
    (u128::from(d2.to_bits()) << 32) | u128::from(index)
}

/// The `(index, squared distance)` of a [`key`].
#[inline]
fn unkey(key: u128) -> (u32, f64) {
    (key as u32, f64::from_bits((key >> 32) as u64))
}

fn finite(p: &Point3<f64>) -> bool {
    p.x.is_finite() && p.y.is_finite() && p.z.is_finite()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The definition: every finite point ranked by squared distance, then index.
    fn brute(points: &[Point3<f64>], i: usize, k: usize) -> Vec<(u32, f64)> {
        if !finite(&points[i]) {
            return Vec::new();
        }
        let mut all: Vec<(u32, f64)> = points
            .iter()
            .enumerate()
            .filter(|(_, p)| finite(p))
            .map(|(j, p)| {
                let (dx, dy, dz) = (p.x - points[i].x, p.y - points[i].y, p.z - points[i].z);
                (j as u32, dx * dx + dy * dy + dz * dz)
            })
            .collect();
        all.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        all.truncate(k);
        all
    }

    fn check(points: &[Point3<f64>], k: usize) -> Result<(), TestCaseError> {
        let near = KNearest::of_each(points, NonZeroUsize::new(k).unwrap()).unwrap();
        prop_assert_eq!(near.len(), points.len());
        for i in 0..points.len() {
            let want = brute(points, i, k);
            prop_assert_eq!(near.of(i), want.as_slice(), "point {}", i);
        }
        Ok(())
    }

    /// A cloud of `n` points of one of several shapes: a noisy surface patch (what views
    /// are), a volume, a line, lattice points (exact ties and duplicates), with a few far
    /// outliers and non-finite points mixed in.
    fn cloud() -> impl Strategy<Value = Vec<Point3<f64>>> {
        (0usize..4, 1usize..400, any::<u64>(), 0usize..4).prop_map(|(shape, n, seed, odd)| {
            let mut s = seed | 1;
            let mut rnd = move || {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (s >> 11) as f64 / (1u64 << 53) as f64
            };
            let mut points: Vec<Point3<f64>> = (0..n)
                .map(|_| {
                    let (u, v, w) = (rnd(), rnd(), rnd());
                    match shape {
                        0 => Point3::new(u * 0.2, v * 0.1, (u * 9.0).sin() * 0.02 + w * 0.002),
                        1 => Point3::new(u, v, w),
                        2 => Point3::new(1.0 + u, 2.0, -3.0),
                        _ => Point3::new(
                            (u * 6.0).floor() * 0.01,
                            (v * 5.0).floor() * 0.01,
                            (w * 2.0).floor() * 0.01,
                        ),
                    }
                })
                .collect();
            for j in 0..odd.min(n) {
                points[j * 7 % n] = match j {
                    0 => Point3::new(50.0, -20.0, 3.0),
                    1 => Point3::new(f64::NAN, 0.0, 0.0),
                    2 => Point3::new(0.0, f64::INFINITY, 0.0),
                    _ => points[(j * 3) % n],
                };
            }
            points
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        #[test]
        fn lists_are_the_k_nearest_by_distance_then_index(points in cloud(), k in 1usize..24) {
            check(&points, k)?;
        }
    }

    #[test]
    fn degenerate_sets() {
        // Extents at the ends of f64's range: no endless layout, the same answers.
        for scale in [1e-310, 1e-200, 1e200, 1e307] {
            let points: Vec<Point3<f64>> = (0..20)
                .map(|i| {
                    Point3::new(
                        i as f64 * scale,
                        -(i as f64) * scale,
                        (i % 3) as f64 * scale,
                    )
                })
                .collect();
            check(&points, 5).unwrap();
        }
        let far = [
            Point3::new(-1e308, 0.0, 0.0),
            Point3::new(1e308, 0.0, 0.0),
            Point3::origin(),
        ];
        let near = KNearest::of_each(&far, NonZeroUsize::new(2).unwrap()).unwrap();
        assert_eq!(near.of(2)[0].0, 2);

        let k = NonZeroUsize::new(4).unwrap();
        assert!(KNearest::of_each(&[], k).unwrap().is_empty());
        let same = vec![Point3::new(1.0, 2.0, 3.0); 6];
        let near = KNearest::of_each(&same, k).unwrap();
        assert_eq!(near.of(5), &[(0, 0.0), (1, 0.0), (2, 0.0), (3, 0.0)]);
        let nan = [Point3::new(f64::NAN, 0.0, 0.0), Point3::origin()];
        let near = KNearest::of_each(&nan, k).unwrap();
        assert!(near.of(0).is_empty());
        assert_eq!(near.of(1), &[(1, 0.0)]);
        assert_eq!(near.k(), 4);
    }
}
