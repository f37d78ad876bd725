//! The render pipelines (one per kind of drawable), the uniform bind-group layout they
//! share, and the unit cube that voxels instance. Built once per [`Renderer`](super::Renderer).

use super::gpu_data::{LineInstance, MeshVertex, PointInstance, VoxelInstance};
use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

/// Colour format of the offscreen target: 8-bit sRGB, what a PNG stores.
pub(crate) const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
/// Depth format of the offscreen target.
pub(crate) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

const GLOBALS: &str = include_str!("shaders/globals.wgsl");
const MESH: &str = include_str!("shaders/mesh.wgsl");
const VOXEL: &str = include_str!("shaders/voxel.wgsl");
const POINTS: &str = include_str!("shaders/points.wgsl");
const LINES: &str = include_str!("shaders/lines.wgsl");

/// A corner of the unit cube `[-0.5, 0.5]³` with its face normal.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct CubeVertex {
    local: [f32; 3],
    normal: [f32; 3],
}

/// The 36 corners (12 outward, counter-clockwise triangles) of the unit cube.
fn unit_cube() -> Vec<CubeVertex> {
    let mut out = Vec::with_capacity(36);
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let mut normal = [0.0f32; 3];
            normal[axis] = sign;
            // Two in-face axes (u, v) with u × v = normal.
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let corner = |su: f32, sv: f32| {
                let mut p = [0.0f32; 3];
                p[axis] = 0.5 * sign;
                p[u] = 0.5 * su * sign;
                p[v] = 0.5 * sv;
                CubeVertex { local: p, normal }
            };
            let quad = [
                corner(-1.0, -1.0),
                corner(1.0, -1.0),
                corner(1.0, 1.0),
                corner(-1.0, 1.0),
            ];
            for i in [0, 1, 2, 0, 2, 3] {
                out.push(quad[i]);
            }
        }
    }
    out
}

/// Pipelines and shared GPU objects.
pub(crate) struct Pipelines {
    pub globals_layout: wgpu::BindGroupLayout,
    pub mesh_opaque: wgpu::RenderPipeline,
    pub mesh_translucent: wgpu::RenderPipeline,
    pub voxel: wgpu::RenderPipeline,
    pub points: wgpu::RenderPipeline,
    pub lines: wgpu::RenderPipeline,
    pub cube: wgpu::Buffer,
    pub cube_vertices: u32,
}

/// One kind of drawable's pipeline: its shaders, vertex buffers and blending.
struct Kind<'a> {
    label: &'a str,
    module: &'a wgpu::ShaderModule,
    vs: &'a str,
    fs: &'a str,
    buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    blend: Option<wgpu::BlendState>,
    depth_write: bool,
    alpha_to_coverage: bool,
}

impl<'a> Kind<'a> {
    /// An opaque kind: no blending, writes depth, no alpha to coverage.
    fn opaque(
        label: &'a str,
        module: &'a wgpu::ShaderModule,
        vs: &'a str,
        fs: &'a str,
        buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    ) -> Self {
        Self {
            label,
            module,
            vs,
            fs,
            buffers,
            blend: None,
            depth_write: true,
            alpha_to_coverage: false,
        }
    }
}

/// Mesh vertices: position, normal, colour.
const MESH_ATTRS: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Unorm8x4];
/// The unit cube's corners: position, normal.
const CUBE_ATTRS: [wgpu::VertexAttribute; 2] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3];
/// Voxel instances: centre, size, colour, shading.
const VOXEL_ATTRS: [wgpu::VertexAttribute; 4] =
    wgpu::vertex_attr_array![2 => Float32x3, 3 => Float32, 4 => Unorm8x4, 5 => Float32];
/// Point instances: position, size, colour.
const POINT_ATTRS: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32, 2 => Unorm8x4];
/// Line instances: start, width, end, colour.
const LINE_ATTRS: [wgpu::VertexAttribute; 4] = wgpu::vertex_attr_array![
    0 => Float32x3, 1 => Float32, 2 => Float32x3, 3 => Unorm8x4
];

/// The vertex buffer of meshes.
fn mesh_buffers() -> [Option<wgpu::VertexBufferLayout<'static>>; 1] {
    [Some(wgpu::VertexBufferLayout {
        array_stride: size_of::<MeshVertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &MESH_ATTRS,
    })]
}

/// The vertex buffers of voxels: the unit cube's corners, instanced per voxel.
fn voxel_buffers() -> [Option<wgpu::VertexBufferLayout<'static>>; 2] {
    [
        Some(wgpu::VertexBufferLayout {
            array_stride: size_of::<CubeVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &CUBE_ATTRS,
        }),
        Some(wgpu::VertexBufferLayout {
            array_stride: size_of::<VoxelInstance>() as u64,
            step_mode: wgpu::VertexStepMode::Instance,
            attributes: &VOXEL_ATTRS,
        }),
    ]
}

/// The instance buffer of point sprites.
fn point_buffers() -> [Option<wgpu::VertexBufferLayout<'static>>; 1] {
    [Some(wgpu::VertexBufferLayout {
        array_stride: size_of::<PointInstance>() as u64,
        step_mode: wgpu::VertexStepMode::Instance,
        attributes: &POINT_ATTRS,
    })]
}

/// The instance buffer of line segments.
fn line_buffers() -> [Option<wgpu::VertexBufferLayout<'static>>; 1] {
    [Some(wgpu::VertexBufferLayout {
        array_stride: size_of::<LineInstance>() as u64,
        step_mode: wgpu::VertexStepMode::Instance,
        attributes: &LINE_ATTRS,
    })]
}

/// The shader modules, each with the shared globals prepended.
struct ShaderModules {
    mesh: wgpu::ShaderModule,
    voxel: wgpu::ShaderModule,
    points: wgpu::ShaderModule,
    lines: wgpu::ShaderModule,
}

impl ShaderModules {
    /// Compiles the modules; the point sprites' cut-off follows `sample_count`.
    fn new(device: &wgpu::Device, sample_count: u32) -> Self {
        let module = |label: &str, body: &str| {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(format!("{GLOBALS}\n{body}").into()),
            })
        };
        let mesh = module("nbv mesh", MESH);
        let voxel = module("nbv voxel", VOXEL);
        // Without multisampling there is no alpha to coverage: cut the sprite at half cover.
        let discard = if sample_count > 1 { "0.0" } else { "0.5" };
        let points = module(
            "nbv points",
            &format!("const POINT_DISCARD_BELOW: f32 = {discard};\n{POINTS}"),
        );
        let lines = module("nbv lines", LINES);
        Self {
            mesh,
            voxel,
            points,
            lines,
        }
    }
}

/// The bind-group layout of the uniform globals every pipeline shares.
fn globals_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("nbv globals"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        }],
    })
}

/// The render pipeline of one kind: triangle lists, no culling, depth test `Less`,
/// `sample_count` samples, drawing into [`COLOR_FORMAT`] and [`DEPTH_FORMAT`].
fn build_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    sample_count: u32,
    k: Kind<'_>,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(k.label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module: k.module,
            entry_point: Some(k.vs),
            compilation_options: Default::default(),
            buffers: k.buffers,
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(k.depth_write),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: wgpu::MultisampleState {
            count: sample_count,
            mask: !0,
            alpha_to_coverage_enabled: k.alpha_to_coverage && sample_count > 1,
        },
        fragment: Some(wgpu::FragmentState {
            module: k.module,
            entry_point: Some(k.fs),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState {
                format: COLOR_FORMAT,
                blend: k.blend,
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

impl Pipelines {
    /// The pipelines of every kind of drawable at `sample_count` samples, and the unit
    /// cube's vertex buffer.
    pub fn new(device: &wgpu::Device, sample_count: u32) -> Self {
        let globals_layout = globals_layout(device);
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("nbv layout"),
            bind_group_layouts: &[Some(&globals_layout)],
            immediate_size: 0,
        });
        let modules = ShaderModules::new(device, sample_count);
        let (mesh_buffers, voxel_buffers) = (mesh_buffers(), voxel_buffers());
        let (point_buffers, line_buffers) = (point_buffers(), line_buffers());
        let build = |k: Kind<'_>| build_pipeline(device, &layout, sample_count, k);
        let mesh = |label| Kind::opaque(label, &modules.mesh, "vs_mesh", "fs_mesh", &mesh_buffers);
        let mesh_opaque = build(mesh("nbv mesh"));
        let mesh_translucent = build(Kind {
            blend: Some(wgpu::BlendState::ALPHA_BLENDING),
            depth_write: false,
            ..mesh("nbv translucent mesh")
        });
        let voxel = build(Kind::opaque(
            "nbv voxels",
            &modules.voxel,
            "vs_voxel",
            "fs_voxel",
            &voxel_buffers,
        ));
        let points = build(Kind {
            alpha_to_coverage: true,
            ..Kind::opaque(
                "nbv points",
                &modules.points,
                "vs_point",
                "fs_point",
                &point_buffers,
            )
        });
        let lines = build(Kind::opaque(
            "nbv lines",
            &modules.lines,
            "vs_line",
            "fs_line",
            &line_buffers,
        ));
        let cube_data = unit_cube();
        let cube = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("nbv unit cube"),
            contents: bytemuck::cast_slice(&cube_data),
            usage: wgpu::BufferUsages::VERTEX,
        });
        Self {
            globals_layout,
            mesh_opaque,
            mesh_translucent,
            voxel,
            points,
            lines,
            cube,
            cube_vertices: cube_data.len() as u32,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_cube_triangles_face_outwards() {
        let cube = unit_cube();
        assert_eq!(cube.len(), 36);
        for tri in cube.chunks(3) {
            let p = |i: usize| nalgebra::Vector3::from(tri[i].local);
            let n = (p(1) - p(0)).cross(&(p(2) - p(0)));
            let normal = nalgebra::Vector3::from(tri[0].normal);
            assert!(n.dot(&normal) > 0.0, "triangle {tri:?}");
            for v in tri {
                assert!(v.local.iter().all(|c| c.abs() == 0.5));
            }
        }
    }
}
