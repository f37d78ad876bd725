//! [`TwinWorld::cast_pinhole`]: the first hit of every pixel ray of a pinhole camera at
//! once — what a depth frame needs, at a fraction of the cost of one query-pipeline cast
//! per ray.
//!
//! All rays of a frame leave one origin, so the colliders are visited once per frame, not
//! once per ray:
//! - every collider (except those of the ignored robot frame) is culled by its world
//!   bounding box against the camera's reach and field of view, which also bounds the
//!   pixels it can cover;
//! - triangle meshes are *rasterised*: each triangle, in the camera frame, covers the
//!   pixels whose ray passes through it — the three edge functions `r·(b×c)`, `r·(c×a)`,
//!   `r·(a×b)` of the pixel ray `r` agree in sign (an exact ray–triangle test, two-sided,
//!   watertight on shared edges: a ray on an edge counts for both triangles) — and its depth
//!   along the optical axis is `det(a, b, c) / (r·n)`;
//! - cuboids are rasterised as their 12 triangles, less the faces turned away from the
//!   camera; cylinders are intersected analytically per covered pixel (the quadric and
//!   the caps); any other shape through parry's own ray cast;
//! - a depth buffer keeps the nearest hit (the first in collider order on an exact tie).
//!
//! Everything is `f64` on the colliders' `f32` geometry, so a range differs from the query
//! pipeline's `f32` cast by rounding only (≲ 1 µm at the Dinast's ranges; the equivalence
//! test in `tests/frame_caster.rs` compares them), except on cylinders, where parry's GJK
//! ray cast strays up to millimetres near the rims and this one is exact. A ray starting
//! inside a cylinder hits it at range 0 (as a `solid` ray cast does); a camera inside a
//! closed mesh sees its inside, one inside a cuboid does not see the cuboid; what lies
//! less than 0.1 mm in front of the camera plane is not seen (colliders are clipped there
//! to bound the pixels they cover). Rows are processed in bands in parallel; the result
//! does not depend on the thread count.

use super::TwinWorld;
use super::ray_caster::RayHit;
use super::twin_world::Owner;
use crate::convert::{from_rapier_pose, to_rapier_point, to_rapier_vector};
use nalgebra::{Matrix3, Point3, Vector3};
use nbv_core::math::Pose;
use nbv_core::rig::{DepthCameraSpec, TruthLabel};
use rapier3d::prelude::*;
use rayon::prelude::*;

/// Rows per band of the depth buffer (the unit of parallel work).
const BAND: usize = 8;

/// Fewest items (pixels, vertices, triangles) per parallel task.
const MIN_LEN: usize = 1024;

/// Depth (m, along the optical axis) below which nothing is seen: the part of a collider
/// closer to the camera plane than this is ignored.
const NEAR: f64 = 1e-4;

/// Inclusive pixel rectangle `[u0, u1] × [v0, v1]`.
#[derive(Debug, Clone, Copy)]
struct Rect {
    u0: usize,
    u1: usize,
    v0: usize,
    v1: usize,
}

/// The 12 triangles of a box whose corner `k` has coordinate `i` at `+half` if bit `i`
/// of `k` is set.
const BOX_TRIANGLES: [[u32; 3]; 12] = [
    [0, 2, 3],
    [0, 3, 1],
    [4, 5, 7],
    [4, 7, 6],
    [0, 1, 5],
    [0, 5, 4],
    [2, 6, 7],
    [2, 7, 3],
    [0, 4, 6],
    [0, 6, 2],
    [1, 3, 7],
    [1, 7, 5],
];

/// How a collider is intersected.
enum Kind {
    /// Rasterised: its triangles are in `Frame::tris`.
    Mesh,
    /// Rasterised as its 12 triangles (`half` extents in the collider frame).
    Cuboid { half: Vector3<f64> },
    /// Quadric and caps in the collider frame (axis y).
    Cylinder { half_height: f64, radius: f64 },
    /// parry's ray cast.
    Other,
}

/// One collider the frame can see.
struct Prim {
    handle: ColliderHandle,
    label: TruthLabel,
    kind: Kind,
    rect: Rect,
    /// Camera-frame ray → collider frame: `origin + t·(rot·r)` (t = depth along the axis).
    origin: Vector3<f64>,
    rot: Matrix3<f64>,
    /// Collider frame → camera frame (normals).
    back: Matrix3<f64>,
}

/// One triangle in the camera frame.
struct Tri {
    /// Edge-function normals `b×c`, `c×a`, `a×b`.
    e: [Vector3<f64>; 3],
    /// `det(a, b, c)`.
    det: f64,
    rect: Rect,
    prim: u32,
}

/// The nearest hit of a pixel so far: depth along the optical axis, collider, triangle.
#[derive(Debug, Clone, Copy)]
struct Best {
    z: f64,
    prim: u32,
    tri: u32,
}

const NONE: Best = Best {
    z: f64::INFINITY,
    prim: u32::MAX,
    tri: u32::MAX,
};

impl TwinWorld {
    /// The first hit of every pixel ray of camera `spec` at world pose `pose` (row-major,
    /// `None` where nothing lies within `reach` along the ray), ignoring the colliders of
    /// robot frame `ignore_frame`. Pixel `(u, v)` looks along
    /// [`DepthCameraSpec::pixel_ray`]. See the [module doc](self) for the method.
    pub fn cast_pinhole(
        &self,
        pose: &Pose,
        spec: &DepthCameraSpec,
        reach: f64,
        ignore_frame: Option<usize>,
    ) -> Vec<Option<RayHit>> {
        self.cast_pinhole_map(pose, spec, reach, ignore_frame, |_, _, hit, _, _| *hit)
    }

    /// [`Self::cast_pinhole`] with `map(u, v, hit, norm, dir)` applied to every hit as it is
    /// found (in parallel; `norm` is the length of the pixel's unnormalised ray
    /// [`DepthCameraSpec::pixel_ray`], `dir` the ray's unit world direction): one array of
    /// what the caller keeps instead of two.
    pub fn cast_pinhole_map<T: Clone + Send>(
        &self,
        pose: &Pose,
        spec: &DepthCameraSpec,
        reach: f64,
        ignore_frame: Option<usize>,
        map: impl Fn(usize, usize, &RayHit, f64, &Vector3<f64>) -> T + Sync,
    ) -> Vec<Option<T>> {
        let (w, h) = (spec.width, spec.height);
        if w == 0 || h == 0 {
            return Vec::new();
        }
        let f = spec.focal();
        let xs: Vec<f64> = (0..w)
            .map(|u| (u as f64 + 0.5 - 0.5 * w as f64) / f)
            .collect();
        let ys: Vec<f64> = (0..h)
            .map(|v| (v as f64 + 0.5 - 0.5 * h as f64) / f)
            .collect();
        let view = Projection {
            w,
            h,
            f,
            reach,
            inverse: pose.inverse(),
        };
        let rotation = *pose.rotation.to_rotation_matrix().matrix();
        let prims = self.visible_prims(&view, ignore_frame);
        let (tris, normals) = self.triangles(&view, &prims, &rotation);
        let bands = h.div_ceil(BAND);
        let mut bins: Vec<Vec<u32>> = vec![Vec::new(); bands];
        for (i, t) in tris.iter().enumerate() {
            for bin in &mut bins[t.rect.v0 / BAND..=t.rect.v1 / BAND] {
                bin.push(i as u32);
            }
        }

        let mut best = vec![NONE; w * h];
        best.par_chunks_mut(w * BAND)
            .enumerate()
            .for_each(|(band, buffer)| {
                let v_first = band * BAND;
                let v_last = v_first + buffer.len() / w - 1;
                for (p, prim) in prims.iter().enumerate() {
                    let r = prim.rect;
                    if matches!(prim.kind, Kind::Mesh | Kind::Cuboid { .. })
                        || r.v1 < v_first
                        || r.v0 > v_last
                    {
                        continue;
                    }
                    for v in r.v0.max(v_first)..=r.v1.min(v_last) {
                        let row = &mut buffer[(v - v_first) * w..][..w];
                        for u in r.u0..=r.u1 {
                            let ray = Vector3::new(xs[u], ys[v], 1.0);
                            if let Some((z, _)) = self.intersect(prim, &ray, pose)
                                && z < row[u].z
                            {
                                row[u] = Best {
                                    z,
                                    prim: p as u32,
                                    tri: u32::MAX,
                                };
                            }
                        }
                    }
                }
                for &i in &bins[band] {
                    let t = &tris[i as usize];
                    let r = t.rect;
                    let [e0, e1, e2] = &t.e;
                    for v in r.v0.max(v_first)..=r.v1.min(v_last) {
                        let y = ys[v];
                        let (c0, c1, c2) = (e0.y * y + e0.z, e1.y * y + e1.z, e2.y * y + e2.z);
                        let row = &mut buffer[(v - v_first) * w..][..w];
                        for u in r.u0..=r.u1 {
                            let x = xs[u];
                            let (s0, s1, s2) = (e0.x * x + c0, e1.x * x + c1, e2.x * x + c2);
                            let inside = (s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0)
                                || (s0 <= 0.0 && s1 <= 0.0 && s2 <= 0.0);
                            if !inside {
                                continue;
                            }
                            let z = t.det / (s0 + s1 + s2);
                            if z > 0.0 && z < row[u].z {
                                row[u] = Best {
                                    z,
                                    prim: t.prim,
                                    tri: i,
                                };
                            }
                        }
                    }
                }
            });

        let origin = Point3::from(pose.translation.vector);
        best.par_iter()
            .with_min_len(MIN_LEN)
            .enumerate()
            .map(|(i, b)| {
                let (u, v) = (i % w, i / w);
                if b.prim == u32::MAX {
                    return None;
                }
                let ray = Vector3::new(xs[u], ys[v], 1.0);
                let norm = ray.norm();
                let distance = b.z * norm;
                if distance > reach {
                    return None;
                }
                let prim = &prims[b.prim as usize];
                let dir = rotation * (ray / norm);
                let normal = if b.tri == u32::MAX {
                    let normal_cam = self.intersect(prim, &ray, pose).map_or(-ray, |(_, n)| n);
                    (rotation * normal_cam).try_normalize(0.0)
                } else {
                    normals[b.tri as usize]
                };
                let mut normal = normal.unwrap_or(-dir);
                if normal.dot(&dir) > 0.0 {
                    normal = -normal;
                }
                let found = RayHit {
                    distance,
                    point: origin + dir * distance,
                    normal,
                    label: prim.label,
                };
                Some(map(u, v, &found, norm, &dir))
            })
            .collect()
    }

    /// The colliders the camera can see, in a fixed order (static bodies, then the robot).
    fn visible_prims(&self, view: &Projection, ignore_frame: Option<usize>) -> Vec<Prim> {
        let mut owned: Vec<(Owner, ColliderHandle)> = self
            .owners
            .iter()
            .filter(|(_, o)| match o {
                Owner::Robot(r) => Some(self.robot_colliders[*r].frame) != ignore_frame,
                Owner::Static(_) => true,
            })
            .map(|(h, o)| (*o, *h))
            .collect();
        owned.sort_by_key(|(o, _)| match o {
            Owner::Static(i) => (0, *i),
            Owner::Robot(i) => (1, *i),
        });
        owned
            .into_iter()
            .filter_map(|(_, handle)| {
                let collider = &self.colliders[handle];
                let aabb = collider.compute_aabb();
                let lo = Vector3::new(aabb.mins.x, aabb.mins.y, aabb.mins.z).cast::<f64>();
                let hi = Vector3::new(aabb.maxs.x, aabb.maxs.y, aabb.maxs.z).cast::<f64>();
                let rect = view.box_rect(&lo, &hi)?;
                let (label, _) = self.label_of(handle)?;
                let shape = collider.shape();
                let kind = if shape.as_trimesh().is_some() {
                    Kind::Mesh
                } else if let Some(c) = shape.as_cuboid() {
                    let e = c.half_extents;
                    Kind::Cuboid {
                        half: Vector3::new(e.x, e.y, e.z).cast::<f64>(),
                    }
                } else if let Some(c) = shape.as_cylinder() {
                    Kind::Cylinder {
                        half_height: f64::from(c.half_height),
                        radius: f64::from(c.radius),
                    }
                } else {
                    Kind::Other
                };
                // camera → collider: collider⁻¹ · camera pose.
                let pose = from_rapier_pose(collider.position());
                let to_local = pose.inverse() * view.inverse.inverse();
                let rot = *to_local.rotation.to_rotation_matrix().matrix();
                Some(Prim {
                    handle,
                    label,
                    kind,
                    rect,
                    origin: to_local.translation.vector,
                    rot,
                    back: rot.transpose(),
                })
            })
            .collect()
    }

    /// The camera-frame triangles of the visible meshes that may cover a pixel, and each
    /// one's unit normal in the world frame (`rotation`: camera → world; `None` if
    /// degenerate), worked out once for all the pixels it covers.
    fn triangles(
        &self,
        view: &Projection,
        prims: &[Prim],
        rotation: &Matrix3<f64>,
    ) -> (Vec<Tri>, Vec<Option<Vector3<f64>>>) {
        let mut tris = (Vec::new(), Vec::new());
        for (p, prim) in prims.iter().enumerate() {
            // collider → camera: the inverse of `rot`, `origin`.
            let to_camera = |v: Vector3<f64>| prim.back * (v - prim.origin);
            let (vertices, indices): (Vec<Vector3<f64>>, &[[u32; 3]]) = match prim.kind {
                Kind::Mesh => {
                    let Some(mesh) = self.colliders[prim.handle].shape().as_trimesh() else {
                        continue;
                    };
                    let vertices = mesh
                        .vertices()
                        .par_iter()
                        .with_min_len(MIN_LEN)
                        .map(|v| to_camera(Vector3::new(v.x, v.y, v.z).cast::<f64>()))
                        .collect();
                    (vertices, mesh.indices())
                }
                Kind::Cuboid { half } => {
                    let corners = (0..8)
                        .map(|k| {
                            let sign = |bit: usize| if k & bit == 0 { -1.0 } else { 1.0 };
                            to_camera(Vector3::new(
                                sign(1) * half.x,
                                sign(2) * half.y,
                                sign(4) * half.z,
                            ))
                        })
                        .collect();
                    (corners, &BOX_TRIANGLES)
                }
                _ => continue,
            };
            let mesh_rect = prim.rect;
            // Each vertex's pixel span, once (a vertex is shared by ~6 triangles); `None`
            // for a vertex less than [`NEAR`] in front of the camera.
            let spans: Vec<Option<PixelSpan>> = vertices
                .par_iter()
                .with_min_len(MIN_LEN)
                .map(|v| view.span_of(v))
                .collect();
            // A box's faces turned away from the camera lie behind its other faces: culled.
            let center =
                matches!(prim.kind, Kind::Cuboid { .. }).then(|| to_camera(Vector3::zeros()));
            tris.par_extend(
                indices
                    .par_iter()
                    .with_min_len(MIN_LEN)
                    .filter_map(|&[i, j, k]| {
                        let [i, j, k] = [i as usize, j as usize, k as usize];
                        let (a, b, c) = (vertices[i], vertices[j], vertices[k]);
                        if a.z > view.reach && b.z > view.reach && c.z > view.reach {
                            return None;
                        }
                        // The pixels first: most triangles of a fine mesh cover no pixel
                        // centre, and need no edge functions.
                        let rect = match (spans[i], spans[j], spans[k]) {
                            (Some(p), Some(q), Some(r)) => PixelSpan::hull(&[p, q, r], mesh_rect),
                            _ => view.rect_of(&[a, b, c], &[(0, 1), (1, 2), (2, 0)], mesh_rect),
                        }?;
                        let e = [b.cross(&c), c.cross(&a), a.cross(&b)];
                        let det = a.dot(&e[0]);
                        if let Some(center) = center {
                            // n = e0 + e1 + e2 = (b − a)×(c − a), det = n·a: the camera
                            // (the origin) is on the outer side iff n·a has the sign
                            // opposite to n·(centroid − centre).
                            let n = e[0] + e[1] + e[2];
                            let outward = n.dot(&((a + b + c) / 3.0 - center));
                            if outward * det >= 0.0 {
                                return None;
                            }
                        }
                        let normal = (rotation * (e[0] + e[1] + e[2])).try_normalize(0.0);
                        let tri = Tri {
                            det,
                            e,
                            rect,
                            prim: p as u32,
                        };
                        Some((tri, normal))
                    }),
            );
        }
        tris
    }

    /// The hit of camera-frame pixel ray `ray` (z = 1) on a non-mesh collider: depth along
    /// the optical axis and the camera-frame surface normal.
    fn intersect(
        &self,
        prim: &Prim,
        ray: &Vector3<f64>,
        pose: &Pose,
    ) -> Option<(f64, Vector3<f64>)> {
        let o = prim.origin;
        let d = prim.rot * ray;
        let (z, n) = match prim.kind {
            Kind::Mesh | Kind::Cuboid { .. } => return None,
            Kind::Cylinder {
                half_height,
                radius,
            } => cylinder(&o, &d, half_height, radius)?,
            Kind::Other => {
                let collider = &self.colliders[prim.handle];
                let norm = ray.norm();
                let dir = pose.rotation * (ray / norm);
                let origin = Point3::from(pose.translation.vector);
                let r = Ray::new(to_rapier_point(&origin), to_rapier_vector(&dir));
                let hit = collider.shape().cast_ray_and_get_normal(
                    collider.position(),
                    &r,
                    f32::MAX,
                    true,
                )?;
                let n = Vector3::new(hit.normal.x, hit.normal.y, hit.normal.z).cast::<f64>();
                let n_cam = pose.rotation.inverse() * n;
                return Some((f64::from(hit.time_of_impact) / norm, n_cam));
            }
        };
        Some((z, prim.back * n))
    }
}

/// The camera's projection and reach.
struct Projection {
    w: usize,
    h: usize,
    f: f64,
    reach: f64,
    /// World → camera.
    inverse: Pose,
}

impl Projection {
    /// The pixel rectangle covered by the world box `[lo, hi]`, `None` if it lies beyond
    /// the reach, behind the camera or outside the image.
    fn box_rect(&self, lo: &Vector3<f64>, hi: &Vector3<f64>) -> Option<Rect> {
        let o = self.inverse.inverse().translation.vector;
        let gap = Vector3::from_fn(|i, _| (lo[i] - o[i]).max(o[i] - hi[i]).max(0.0));
        if gap.norm() > self.reach {
            return None;
        }
        let corners: Vec<Vector3<f64>> = (0..8)
            .map(|k| {
                let c = Vector3::new(
                    if k & 1 == 0 { lo.x } else { hi.x },
                    if k & 2 == 0 { lo.y } else { hi.y },
                    if k & 4 == 0 { lo.z } else { hi.z },
                );
                self.inverse * Point3::from(c)
            })
            .map(|p| p.coords)
            .collect();
        const EDGES: [(usize, usize); 12] = [
            (0, 1),
            (2, 3),
            (4, 5),
            (6, 7),
            (0, 2),
            (1, 3),
            (4, 6),
            (5, 7),
            (0, 4),
            (1, 5),
            (2, 6),
            (3, 7),
        ];
        self.rect_of(&corners, &EDGES, self.full())
    }

    /// The pixel centres camera-frame point `p` may cover ([`PixelSpan`]), `None` if it
    /// lies less than [`NEAR`] in front of the camera.
    fn span_of(&self, p: &Vector3<f64>) -> Option<PixelSpan> {
        (p.z >= NEAR).then(|| self.span_at(p.x / p.z, p.y / p.z))
    }

    /// The [`PixelSpan`] of image-plane point `(x, y)` (`x/z`, `y/z`).
    fn span_at(&self, x: f64, y: f64) -> PixelSpan {
        // Pixel u's centre is at x = (u + 0.5 − w/2) / f: the pixels whose centres lie
        // within 10⁻³ pixel of the point, a margin far above the rounding of the
        // projection (the edge functions decide exactly).
        let u = x * self.f + 0.5 * self.w as f64 - 0.5;
        let v = y * self.f + 0.5 * self.h as f64 - 0.5;
        PixelSpan {
            u0: ceil_clamped(u - 1e-3, self.w),
            u1: floor_clamped(u + 1e-3, self.w),
            v0: ceil_clamped(v - 1e-3, self.h),
            v1: floor_clamped(v + 1e-3, self.h),
        }
    }

    fn full(&self) -> Rect {
        Rect {
            u0: 0,
            u1: self.w - 1,
            v0: 0,
            v1: self.h - 1,
        }
    }

    /// The pixels whose rays may meet the convex hull of camera-frame points `points`
    /// (with its edges `edges`), clipped to `within`. Only the part at least [`NEAR`] in
    /// front of the camera counts: the hull is clipped at that plane.
    fn rect_of(
        &self,
        points: &[Vector3<f64>],
        edges: &[(usize, usize)],
        within: Rect,
    ) -> Option<Rect> {
        let mut spans: Vec<PixelSpan> = points.iter().filter_map(|p| self.span_of(p)).collect();
        if spans.is_empty() {
            return None;
        }
        if spans.len() < points.len() {
            for &(i, j) in edges {
                let (p, q) = (points[i], points[j]);
                if (p.z < NEAR) != (q.z < NEAR) {
                    let clipped = p + (q - p) * ((NEAR - p.z) / (q.z - p.z));
                    spans.push(self.span_at(clipped.x / clipped.z, clipped.y / clipped.z));
                }
            }
        }
        PixelSpan::hull(&spans, within)
    }
}

/// The pixel centres within 10⁻³ pixel of a projected point, as integer bounds (an empty
/// range, `u1 < u0`, where no centre is that close), clamped to the image ± 2. The bounds
/// of a convex hull's pixels are the extremes of its corners' spans: rounding commutes with
/// taking the extreme, so a hull's rectangle is integer work once its corners are known.
#[derive(Debug, Clone, Copy)]
struct PixelSpan {
    u0: i32,
    u1: i32,
    v0: i32,
    v1: i32,
}

impl PixelSpan {
    /// The pixels of the hull of points with spans `spans`, clipped to `within` (`None` if
    /// none).
    fn hull(spans: &[PixelSpan], within: Rect) -> Option<Rect> {
        let (mut u0, mut u1, mut v0, mut v1) = (i32::MAX, i32::MIN, i32::MAX, i32::MIN);
        for s in spans {
            u0 = u0.min(s.u0);
            u1 = u1.max(s.u1);
            v0 = v0.min(s.v0);
            v1 = v1.max(s.v1);
        }
        // Image sizes fit an i32 (a frame's pixels are indexed by u32 elsewhere).
        let clip = |lo: i32, hi: i32, min: usize, max: usize| {
            let (lo, hi) = (lo.max(min as i32), hi.min(max as i32));
            (lo <= hi).then_some((lo as usize, hi as usize))
        };
        let (u0, u1) = clip(u0, u1, within.u0, within.u1)?;
        let (v0, v1) = clip(v0, v1, within.v0, within.v1)?;
        Some(Rect { u0, u1, v0, v1 })
    }
}

/// `⌈t⌉` for `t` clamped to `[−2, size + 2]` (no libm call: the conversion truncates
/// exactly in that range).
fn ceil_clamped(t: f64, size: usize) -> i32 {
    let t = t.clamp(-2.0, size as f64 + 2.0);
    let i = t as i32;
    if f64::from(i) < t { i + 1 } else { i }
}

/// `⌊t⌋` for `t` clamped to `[−2, size + 2]`.
fn floor_clamped(t: f64, size: usize) -> i32 {
    let t = t.clamp(-2.0, size as f64 + 2.0);
    let i = t as i32;
    if f64::from(i) > t { i - 1 } else { i }
}

/// First hit (`t` ≥ 0) of `o + t·d` on the capped cylinder of axis y, `|y| ≤ half_height`,
/// `x² + z² ≤ radius²`, with its outward normal; 0 from inside.
fn cylinder(
    o: &Vector3<f64>,
    d: &Vector3<f64>,
    half_height: f64,
    radius: f64,
) -> Option<(f64, Vector3<f64>)> {
    let r2 = radius * radius;
    if o.y.abs() <= half_height && o.x * o.x + o.z * o.z <= r2 {
        return Some((0.0, -d));
    }
    let mut best: Option<(f64, Vector3<f64>)> = None;
    let mut take = |t: f64, n: Vector3<f64>| {
        if t >= 0.0 && best.is_none_or(|(b, _)| t < b) {
            best = Some((t, n));
        }
    };
    // The side.
    let a = d.x * d.x + d.z * d.z;
    if a > 0.0 {
        let b = o.x * d.x + o.z * d.z;
        let c = o.x * o.x + o.z * o.z - r2;
        let disc = b * b - a * c;
        if disc >= 0.0 {
            let t = (-b - disc.sqrt()) / a;
            let p = o + d * t;
            if p.y.abs() <= half_height {
                take(t, Vector3::new(p.x, 0.0, p.z));
            }
        }
    }
    // The caps.
    if d.y != 0.0 {
        for cap in [-half_height, half_height] {
            let t = (cap - o.y) / d.y;
            let p = o + d * t;
            if p.x * p.x + p.z * p.z <= r2 {
                take(t, Vector3::new(0.0, cap.signum(), 0.0));
            }
        }
    }
    best
}
