//! [`Renderer`]: one headless wgpu device (hardware or software adapter) and its
//! pipelines, drawing [`RenderScene`]s into an offscreen multisampled texture and reading
//! the resolved pixels back into an [`RgbaImage`].

use super::gpu_data::{Globals, SceneData};
use super::pipelines::{COLOR_FORMAT, DEPTH_FORMAT, Pipelines};
use super::{Camera, RenderError, RenderScene};
use image::RgbaImage;
use std::sync::{Mutex, mpsc};
use wgpu::util::DeviceExt;

/// How a [`Renderer`] picks its adapter and anti-aliases.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RendererOptions {
    /// Backends to try; `None` reads `WGPU_BACKEND` (for example `vulkan` or `gl`) and
    /// otherwise tries every backend built in.
    pub backends: Option<wgpu::Backends>,
    /// Multisample anti-aliasing (4 samples) when the adapter supports it.
    pub multisample: bool,
}

impl Default for RendererOptions {
    fn default() -> Self {
        Self {
            backends: None,
            multisample: true,
        }
    }
}

/// Offscreen targets of one image size, kept between renders of that size.
struct Targets {
    width: u32,
    height: u32,
    padded_row: u32,
    msaa_view: Option<wgpu::TextureView>,
    resolve: wgpu::Texture,
    resolve_view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    readback: wgpu::Buffer,
}

/// A headless renderer: one wgpu device reused for many pictures.
///
/// ```
/// use nbv_sim::render::{Camera, RenderScene, Renderer};
/// use nalgebra::Point3;
/// let Some(renderer) = Renderer::optional() else { return }; // warns without an adapter
/// let camera = Camera::look_at(Point3::new(-1.0, 0.0, 1.0), Point3::new(1.0, 0.0, 0.5));
/// let image = renderer.render(&RenderScene::new(), &camera, 320, 240).unwrap();
/// assert_eq!(image.dimensions(), (320, 240));
/// ```
pub struct Renderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    sample_count: u32,
    pipelines: Pipelines,
    targets: Mutex<Option<Targets>>,
}

impl std::fmt::Debug for Renderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Renderer")
            .field("adapter", &self.adapter_summary())
            .field("sample_count", &self.sample_count)
            .finish_non_exhaustive()
    }
}

impl Renderer {
    /// A renderer on the first adapter wgpu offers (hardware first, then a software
    /// fallback), honouring `WGPU_BACKEND`, with 4× anti-aliasing where supported.
    pub fn new() -> Result<Self, RenderError> {
        Self::with_options(&RendererOptions::default())
    }

    /// Like [`Renderer::new`], but logs the reason as a warning and returns `None` when no
    /// renderer can be made: for commands whose pictures only add to other work.
    pub fn optional() -> Option<Self> {
        match Self::new() {
            Ok(r) => Some(r),
            Err(e) => {
                tracing::warn!("pictures skipped: {e}");
                None
            }
        }
    }

    /// A renderer with explicit options.
    pub fn with_options(options: &RendererOptions) -> Result<Self, RenderError> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        if let Some(b) = options.backends {
            desc.backends = b;
        }
        let backends = desc.backends;
        let instance = wgpu::Instance::new(desc);
        let power_preference = wgpu::PowerPreference::from_env().unwrap_or_default();
        let mut failure = String::new();
        let mut adapter = None;
        for force_fallback_adapter in [false, true] {
            let request = instance.request_adapter(&wgpu::RequestAdapterOptions {
                power_preference,
                force_fallback_adapter,
                compatible_surface: None,
                apply_limit_buckets: false,
            });
            match pollster::block_on(request) {
                Ok(a) => {
                    adapter = Some(a);
                    break;
                }
                Err(e) => failure = e.to_string(),
            }
        }
        let Some(adapter) = adapter else {
            return Err(RenderError::NoAdapter {
                backends: backend_names(backends),
                detail: failure,
            });
        };
        let info = adapter.get_info();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("nbv renderer"),
            required_features: wgpu::Features::empty(),
            required_limits: adapter.limits(),
            memory_hints: wgpu::MemoryHints::MemoryUsage,
            ..Default::default()
        }))
        .map_err(|e| RenderError::NoDevice {
            adapter: format!("{} ({:?})", info.name, info.backend),
            detail: e.to_string(),
        })?;
        let supports_4x = |format| {
            let f = adapter.get_texture_format_features(format);
            f.flags.sample_count_supported(4)
                && f.allowed_usages
                    .contains(wgpu::TextureUsages::RENDER_ATTACHMENT)
        };
        let resolvable = adapter
            .get_texture_format_features(COLOR_FORMAT)
            .flags
            .contains(wgpu::TextureFormatFeatureFlags::MULTISAMPLE_RESOLVE);
        let sample_count = if options.multisample
            && supports_4x(COLOR_FORMAT)
            && supports_4x(DEPTH_FORMAT)
            && resolvable
        {
            4
        } else {
            1
        };
        let pipelines = {
            let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
            let p = Pipelines::new(&device, sample_count);
            if let Some(e) = pollster::block_on(scope.pop()) {
                return Err(RenderError::Gpu(format!("building the pipelines: {e}")));
            }
            p
        };
        tracing::debug!(
            "renderer on {} ({:?}, {:?}), {sample_count}x MSAA",
            info.name,
            info.backend,
            info.device_type
        );
        Ok(Self {
            device,
            queue,
            info,
            sample_count,
            pipelines,
            targets: Mutex::new(None),
        })
    }

    /// The adapter in use.
    pub fn adapter_info(&self) -> &wgpu::AdapterInfo {
        &self.info
    }

    /// One line naming the adapter, its backend and device type.
    pub fn adapter_summary(&self) -> String {
        format!(
            "{} ({:?}, {:?}, driver {})",
            self.info.name, self.info.backend, self.info.device_type, self.info.driver_info
        )
    }

    /// Samples per pixel: 4 with anti-aliasing, 1 without.
    pub fn sample_count(&self) -> u32 {
        self.sample_count
    }

    /// Renders `scene` seen by `camera` into a `width × height` opaque RGBA image
    /// (sRGB, row 0 at the top).
    pub fn render(
        &self,
        scene: &RenderScene,
        camera: &Camera,
        width: u32,
        height: u32,
    ) -> Result<RgbaImage, RenderError> {
        let limits = self.device.limits();
        let max = limits.max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(RenderError::BadSize { width, height, max });
        }
        scene.points.iter().try_for_each(|p| p.check())?;
        scene.voxels.iter().try_for_each(|v| v.check())?;
        scene.lines.iter().try_for_each(|l| l.check())?;
        let data = SceneData::pack(scene);
        if data.skipped > 0 {
            tracing::warn!(
                "render: {} items with non-finite coordinates or bad indices were left out",
                data.skipped
            );
        }
        let max_buffer = limits.max_buffer_size;
        let fits = |what: &'static str, bytes: usize| {
            let bytes = bytes as u64;
            if bytes > max_buffer {
                Err(RenderError::TooLarge {
                    what,
                    bytes,
                    max: max_buffer,
                })
            } else {
                Ok(())
            }
        };
        fits("meshes", size_of_val(data.opaque.as_slice()))?;
        fits(
            "translucent meshes",
            size_of_val(data.translucent.as_slice()),
        )?;
        fits("voxels", size_of_val(data.voxels.as_slice()))?;
        fits("points", size_of_val(data.points.as_slice()))?;
        fits("lines", size_of_val(data.lines.as_slice()))?;

        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let result = self.draw(&data, scene, camera, width, height);
        let invalid = pollster::block_on(validation.pop());
        let out_of_memory = pollster::block_on(oom.pop());
        if let Some(e) = invalid.or(out_of_memory) {
            return Err(RenderError::Gpu(e.to_string()));
        }
        result
    }

    fn draw(
        &self,
        data: &SceneData,
        scene: &RenderScene,
        camera: &Camera,
        width: u32,
        height: u32,
    ) -> Result<RgbaImage, RenderError> {
        let mut guard = self.targets.lock().unwrap_or_else(|e| e.into_inner());
        let targets = match guard.take() {
            Some(t) if t.width == width && t.height == height => t,
            _ => self.make_targets(width, height),
        };
        let globals = Globals::new(camera, &scene.lighting, width, height);
        let globals_buffer = self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("nbv globals"),
                contents: bytemuck::bytes_of(&globals),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        let bind_group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("nbv globals"),
            layout: &self.pipelines.globals_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: globals_buffer.as_entire_binding(),
            }],
        });
        let upload = |label: &str, bytes: &[u8]| {
            (!bytes.is_empty()).then(|| {
                self.device
                    .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some(label),
                        contents: bytes,
                        usage: wgpu::BufferUsages::VERTEX,
                    })
            })
        };
        let opaque = upload("nbv meshes", bytemuck::cast_slice(&data.opaque));
        let translucent = upload("nbv translucent", bytemuck::cast_slice(&data.translucent));
        let voxels = upload("nbv voxels", bytemuck::cast_slice(&data.voxels));
        let points = upload("nbv points", bytemuck::cast_slice(&data.points));
        let lines = upload("nbv lines", bytemuck::cast_slice(&data.lines));

        let [r, g, b, _] = scene.background.to_linear();
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("nbv frame"),
            });
        {
            let (view, resolve_target) = match &targets.msaa_view {
                Some(msaa) => (msaa, Some(&targets.resolve_view)),
                None => (&targets.resolve_view, None),
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("nbv scene"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &targets.depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                ..Default::default()
            });
            pass.set_bind_group(0, &bind_group, &[]);
            let p = &self.pipelines;
            if let Some(buf) = &opaque {
                pass.set_pipeline(&p.mesh_opaque);
                pass.set_vertex_buffer(0, buf.slice(..));
                pass.draw(0..data.opaque.len() as u32, 0..1);
            }
            if let Some(buf) = &voxels {
                pass.set_pipeline(&p.voxel);
                pass.set_vertex_buffer(0, p.cube.slice(..));
                pass.set_vertex_buffer(1, buf.slice(..));
                pass.draw(0..p.cube_vertices, 0..data.voxels.len() as u32);
            }
            if let Some(buf) = &points {
                pass.set_pipeline(&p.points);
                pass.set_vertex_buffer(0, buf.slice(..));
                pass.draw(0..6, 0..data.points.len() as u32);
            }
            if let Some(buf) = &lines {
                pass.set_pipeline(&p.lines);
                pass.set_vertex_buffer(0, buf.slice(..));
                pass.draw(0..6, 0..data.lines.len() as u32);
            }
            if let Some(buf) = &translucent {
                pass.set_pipeline(&p.mesh_translucent);
                pass.set_vertex_buffer(0, buf.slice(..));
                pass.draw(0..data.translucent.len() as u32, 0..1);
            }
        }
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &targets.resolve,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &targets.readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(targets.padded_row),
                    rows_per_image: Some(height),
                },
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        );
        self.queue.submit([encoder.finish()]);
        let pixels = self.read_back(&targets);
        *guard = Some(targets);
        let pixels = pixels?;
        RgbaImage::from_raw(width, height, pixels)
            .ok_or_else(|| RenderError::Gpu("read back a buffer of the wrong size".into()))
    }

    /// Maps the readback buffer and strips the row padding; alpha is forced opaque.
    fn read_back(&self, targets: &Targets) -> Result<Vec<u8>, RenderError> {
        let slice = targets.readback.slice(..);
        let (tx, rx) = mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            // The receiver only disappears if this function already returned.
            let _ = tx.send(r);
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| RenderError::Gpu(format!("waiting for the frame: {e}")))?;
        rx.recv()
            .map_err(|_| RenderError::Gpu("the frame's readback never completed".into()))?
            .map_err(|e| RenderError::Gpu(format!("mapping the frame: {e}")))?;
        let row = targets.width as usize * 4;
        let mut pixels = Vec::with_capacity(row * targets.height as usize);
        {
            let mapped = slice
                .get_mapped_range()
                .map_err(|e| RenderError::Gpu(format!("reading the frame: {e}")))?;
            for chunk in mapped.chunks(targets.padded_row as usize) {
                pixels.extend_from_slice(chunk.get(..row).unwrap_or(chunk));
            }
        }
        targets.readback.unmap();
        for px in pixels.chunks_exact_mut(4) {
            px[3] = 255;
        }
        Ok(pixels)
    }

    fn make_targets(&self, width: u32, height: u32) -> Targets {
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let texture = |label, format, samples, usage| {
            self.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count: samples,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let resolve = texture(
            "nbv colour",
            COLOR_FORMAT,
            1,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let msaa_view = (self.sample_count > 1).then(|| {
            texture(
                "nbv colour msaa",
                COLOR_FORMAT,
                self.sample_count,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            )
            .create_view(&Default::default())
        });
        let depth_view = texture(
            "nbv depth",
            DEPTH_FORMAT,
            self.sample_count,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .create_view(&Default::default());
        let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let padded_row = (width * 4).div_ceil(align) * align;
        let readback = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("nbv readback"),
            size: u64::from(padded_row) * u64::from(height),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Targets {
            width,
            height,
            padded_row,
            msaa_view,
            resolve_view: resolve.create_view(&Default::default()),
            resolve,
            depth_view,
            readback,
        }
    }
}

fn backend_names(b: wgpu::Backends) -> String {
    let names: Vec<&str> = [
        (wgpu::Backends::VULKAN, "vulkan"),
        (wgpu::Backends::GL, "gl"),
        (wgpu::Backends::METAL, "metal"),
        (wgpu::Backends::DX12, "dx12"),
        (wgpu::Backends::BROWSER_WEBGPU, "webgpu"),
    ]
    .into_iter()
    .filter(|(flag, _)| b.contains(*flag))
    .map(|(_, n)| n)
    .collect();
    if names.is_empty() {
        "none".into()
    } else {
        names.join(", ")
    }
}
