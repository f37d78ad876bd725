//! The GPU-side layout of a [`RenderScene`]: vertex and instance records, the per-frame
//! uniform block, and the packing of the scene's drawables into them (world coordinates
//! in f32, colours as 8-bit sRGB, non-finite items dropped and counted).

use super::{Camera, Lighting, MeshItem, RenderScene, Shading};
use bytemuck::{Pod, Zeroable};
use nalgebra::{Point3, Vector3};

/// One corner of a mesh triangle: world position, world normal, sRGB colour.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct MeshVertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub color: [u8; 4],
}

/// One voxel cube: centre, edge length, sRGB colour, outline darkening.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct VoxelInstance {
    pub center: [f32; 3],
    pub size: f32,
    pub color: [u8; 4],
    pub outline: f32,
}

/// One point sprite: position, diameter in pixels, sRGB colour.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct PointInstance {
    pub position: [f32; 3],
    pub size: f32,
    pub color: [u8; 4],
}

/// One line segment: end `a`, width in pixels, end `b`, sRGB colour.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct LineInstance {
    pub a: [f32; 3],
    pub width: f32,
    pub b: [f32; 3],
    pub color: [u8; 4],
}

/// The per-frame uniform block shared by every shader (see `shaders/globals.wgsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct Globals {
    pub view_proj: [[f32; 4]; 4],
    pub eye: [f32; 4],
    /// World direction towards the key light, and its intensity.
    pub key: [f32; 4],
    /// World direction towards the fill light, and its intensity.
    pub fill: [f32; 4],
    /// Ambient, specular strength, shininess, unused.
    pub params: [f32; 4],
    /// Width, height, 1/width, 1/height in pixels.
    pub viewport: [f32; 4],
}

impl Globals {
    pub fn new(camera: &Camera, lighting: &Lighting, width: u32, height: u32) -> Self {
        let (w, h) = (f64::from(width), f64::from(height));
        let vp = camera.view_projection(w / h);
        let mut view_proj = [[0.0f32; 4]; 4];
        for (c, col) in view_proj.iter_mut().enumerate() {
            for (r, v) in col.iter_mut().enumerate() {
                *v = vp[(r, c)] as f32;
            }
        }
        let (right, up, forward) = camera.basis();
        let to_world = |d: &Vector3<f64>| {
            let v = right * d.x + up * d.y - forward * d.z;
            v.try_normalize(1e-12).unwrap_or_else(|| -forward)
        };
        let dir4 = |d: Vector3<f64>, i: f64| [d.x as f32, d.y as f32, d.z as f32, i as f32];
        Self {
            view_proj,
            eye: [
                camera.eye.x as f32,
                camera.eye.y as f32,
                camera.eye.z as f32,
                1.0,
            ],
            key: dir4(to_world(&lighting.key_direction), lighting.key),
            fill: dir4(to_world(&lighting.fill_direction), lighting.fill),
            params: [
                lighting.ambient as f32,
                lighting.specular as f32,
                lighting.shininess.max(1.0) as f32,
                0.0,
            ],
            viewport: [w as f32, h as f32, (1.0 / w) as f32, (1.0 / h) as f32],
        }
    }
}

/// A scene packed for the GPU.
#[derive(Debug, Default)]
pub(crate) struct SceneData {
    pub opaque: Vec<MeshVertex>,
    pub translucent: Vec<MeshVertex>,
    pub voxels: Vec<VoxelInstance>,
    pub points: Vec<PointInstance>,
    pub lines: Vec<LineInstance>,
    /// Items dropped for non-finite coordinates or out-of-range indices.
    pub skipped: usize,
}

fn finite3(p: &Point3<f64>) -> Option<[f32; 3]> {
    let v = [p.x as f32, p.y as f32, p.z as f32];
    v.iter().all(|c| c.is_finite()).then_some(v)
}

/// Cosine of the crease angle of [`Shading::Smooth`] (40°).
const CREASE_COS: f64 = 0.766;

impl SceneData {
    /// Packs a scene whose colour arrays have been checked.
    pub fn pack(scene: &RenderScene) -> Self {
        let mut data = Self::default();
        for m in &scene.meshes {
            data.pack_mesh(m);
        }
        for set in &scene.voxels {
            let size = set.size.abs() as f32;
            if !(size.is_finite() && size > 0.0) {
                data.skipped += set.centers.len();
                continue;
            }
            let outline = if set.outline.is_finite() {
                set.outline.clamp(0.0, 1.0)
            } else {
                0.0
            };
            for (i, c) in set.centers.iter().enumerate() {
                match (finite3(c), set.color_of(i)) {
                    (Some(center), Some(color)) => data.voxels.push(VoxelInstance {
                        center,
                        size,
                        color: color.to_srgb8(),
                        outline,
                    }),
                    _ => data.skipped += 1,
                }
            }
        }
        for set in &scene.points {
            let size = if set.size.is_finite() {
                set.size.clamp(1.0, 256.0)
            } else {
                1.0
            };
            for (i, p) in set.points.iter().enumerate() {
                match (finite3(p), set.color_of(i)) {
                    (Some(position), Some(color)) => data.points.push(PointInstance {
                        position,
                        size,
                        color: color.to_srgb8(),
                    }),
                    _ => data.skipped += 1,
                }
            }
        }
        for set in &scene.lines {
            let width = if set.width.is_finite() {
                set.width.clamp(1.0, 64.0)
            } else {
                1.0
            };
            for (i, [a, b]) in set.segments.iter().enumerate() {
                match (finite3(a), finite3(b), set.color_of(i)) {
                    (Some(a), Some(b), Some(color)) => data.lines.push(LineInstance {
                        a,
                        width,
                        b,
                        color: color.to_srgb8(),
                    }),
                    _ => data.skipped += 1,
                }
            }
        }
        data
    }

    fn pack_mesh(&mut self, item: &MeshItem) {
        let color = item.color.to_srgb8();
        if color[3] == 0 {
            return;
        }
        let out = if color[3] == 255 {
            &mut self.opaque
        } else {
            &mut self.translucent
        };
        let world: Vec<Point3<f64>> = item.mesh.vertices.iter().map(|v| item.pose * v).collect();
        // Valid triangles with their area-weighted normals.
        let mut tris: Vec<([u32; 3], Vector3<f64>)> = Vec::with_capacity(item.mesh.triangles.len());
        for t in &item.mesh.triangles {
            let corners = t.map(|i| world.get(i as usize).and_then(finite3));
            if corners.iter().any(Option::is_none) {
                self.skipped += 1;
                continue;
            }
            let [a, b, c] = t.map(|i| world[i as usize]);
            let n = (b - a).cross(&(c - a));
            if n.norm_squared() > 0.0 {
                tris.push((*t, n));
            }
        }
        let mut around: Vec<Vec<u32>> = Vec::new();
        if item.shading == Shading::Smooth {
            around = vec![Vec::new(); world.len()];
            for (k, (t, _)) in tris.iter().enumerate() {
                for &v in t {
                    around[v as usize].push(k as u32);
                }
            }
        }
        out.reserve(3 * tris.len());
        for (t, n) in &tris {
            let unit = n.normalize();
            for &v in t {
                let normal = match item.shading {
                    Shading::Flat => unit,
                    Shading::Smooth => around[v as usize]
                        .iter()
                        .map(|&k| tris[k as usize].1)
                        .filter(|m| m.normalize().dot(&unit) >= CREASE_COS)
                        .sum::<Vector3<f64>>()
                        .try_normalize(0.0)
                        .unwrap_or(unit),
                };
                let p = world[v as usize];
                out.push(MeshVertex {
                    position: [p.x as f32, p.y as f32, p.z as f32],
                    normal: [normal.x as f32, normal.y as f32, normal.z as f32],
                    color,
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{Color, PointSet, tessellate};
    use nalgebra::Isometry3;

    #[test]
    fn flat_cube_has_36_corners_with_axis_normals() {
        let mut scene = RenderScene::new();
        scene.add_mesh(MeshItem::flat(
            tessellate::cuboid([1.0, 1.0, 1.0]),
            Isometry3::translation(1.0, 0.0, 0.0),
            Color::WHITE,
        ));
        let d = SceneData::pack(&scene);
        assert_eq!(d.opaque.len(), 36);
        for v in &d.opaque {
            let n = Vector3::new(v.normal[0], v.normal[1], v.normal[2]);
            assert!((n.norm() - 1.0).abs() < 1e-6);
            assert!(n.iter().filter(|c| c.abs() > 0.999).count() == 1);
            // Outward: the normal points away from the cube centre along its axis.
            let rel = Vector3::new(v.position[0] - 1.0, v.position[1], v.position[2]);
            assert!(n.dot(&rel) > 0.0);
        }
    }

    #[test]
    fn smooth_sphere_normals_are_radial() {
        let mut scene = RenderScene::new();
        scene.add_mesh(MeshItem::smooth(
            tessellate::sphere(1.0, 12, 24),
            Isometry3::identity(),
            Color::WHITE,
        ));
        let d = SceneData::pack(&scene);
        for v in &d.opaque {
            let p = Vector3::new(v.position[0], v.position[1], v.position[2]).normalize();
            let n = Vector3::new(v.normal[0], v.normal[1], v.normal[2]);
            assert!(p.dot(&n) > 0.98, "normal {n:?} at {p:?}");
        }
    }

    #[test]
    fn smooth_cylinder_keeps_cap_edges_sharp() {
        let mut scene = RenderScene::new();
        scene.add_mesh(MeshItem::smooth(
            tessellate::cylinder(1.0, 1.0, 32),
            Isometry3::identity(),
            Color::WHITE,
        ));
        let d = SceneData::pack(&scene);
        // Every corner's normal is either the cap's axis or horizontal.
        for v in &d.opaque {
            let nz = v.normal[2].abs();
            assert!(!(1e-6..=0.999).contains(&nz), "normal {:?}", v.normal);
        }
    }

    #[test]
    fn bad_items_are_skipped_and_counted() {
        let mut scene = RenderScene::new();
        scene.add_points(PointSet::uniform(
            vec![Point3::origin(), Point3::new(f64::NAN, 0.0, 0.0)],
            Color::BLACK,
            3.0,
        ));
        let mut mesh = tessellate::cuboid([1.0, 1.0, 1.0]);
        mesh.triangles.push([0, 1, 99]);
        scene.add_mesh(MeshItem::flat(
            mesh,
            Isometry3::identity(),
            Color::WHITE.with_alpha(0.5),
        ));
        let d = SceneData::pack(&scene);
        assert_eq!(d.points.len(), 1);
        assert_eq!(d.translucent.len(), 36);
        assert_eq!(d.skipped, 2);
    }
}
