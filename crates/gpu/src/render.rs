//! The headless GPU renderer: the scenes of `specula-render`, drawn by wgpu.
//!
//! The image is rendered at `samples` times the resolution into an `Rgba32Float` target,
//! read back and box-filtered on the CPU, exactly as the CPU renderer filters its samples, so
//! the two backends differ only in rasterization and arithmetic details.

use glam::Vec3;
use specula_render::{Image, Scene, Shading};
use wgpu::util::DeviceExt;

use crate::uniforms::{FrameBlock, LightBlock, MaterialBlock};
use crate::{wgsl, Gpu, GpuError};

const COLOUR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Position, normal, anchor: nine floats per vertex.
const VERTEX_FLOATS: usize = 9;

/// Compiled render pipelines (with and without back-face culling) on one GPU.
#[derive(Debug)]
pub struct GpuRenderer<'gpu> {
    gpu: &'gpu Gpu,
    culled: wgpu::RenderPipeline,
    unculled: wgpu::RenderPipeline,
}

/// One object's geometry as the shaders take it.
struct ObjectBuffers {
    vertices: wgpu::Buffer,
    indices: Option<(wgpu::Buffer, u32)>,
    vertex_count: u32,
    material: wgpu::BindGroup,
}

impl<'gpu> GpuRenderer<'gpu> {
    /// Compiles the render module on `gpu`.
    pub fn new(gpu: &'gpu Gpu) -> Result<Self, GpuError> {
        gpu.checked(|| {
            let module = gpu
                .device
                .create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some("specula render"),
                    source: wgpu::ShaderSource::Wgsl(wgsl::render_module().into()),
                });
            let pipeline = |cull_mode| {
                gpu.device
                    .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                        label: Some("specula render"),
                        layout: None,
                        vertex: wgpu::VertexState {
                            module: &module,
                            entry_point: Some("vs_main"),
                            compilation_options: wgpu::PipelineCompilationOptions::default(),
                            buffers: &[Some(wgpu::VertexBufferLayout {
                                array_stride: (VERTEX_FLOATS * 4) as u64,
                                step_mode: wgpu::VertexStepMode::Vertex,
                                attributes: &wgpu::vertex_attr_array![
                                    0 => Float32x3, 1 => Float32x3, 2 => Float32x3
                                ],
                            })],
                        },
                        primitive: wgpu::PrimitiveState {
                            topology: wgpu::PrimitiveTopology::TriangleList,
                            front_face: wgpu::FrontFace::Ccw,
                            cull_mode,
                            ..wgpu::PrimitiveState::default()
                        },
                        depth_stencil: Some(wgpu::DepthStencilState {
                            format: DEPTH_FORMAT,
                            depth_write_enabled: Some(true),
                            depth_compare: Some(wgpu::CompareFunction::Less),
                            stencil: wgpu::StencilState::default(),
                            bias: wgpu::DepthBiasState::default(),
                        }),
                        multisample: wgpu::MultisampleState::default(),
                        fragment: Some(wgpu::FragmentState {
                            module: &module,
                            entry_point: Some("fs_main"),
                            compilation_options: wgpu::PipelineCompilationOptions::default(),
                            targets: &[Some(COLOUR_FORMAT.into())],
                        }),
                        multiview_mask: None,
                        cache: None,
                    })
            };
            Self {
                gpu,
                culled: pipeline(Some(wgpu::Face::Back)),
                unculled: pipeline(None),
            }
        })
    }

    /// Refuses sizes the CPU renderer refuses or the adapter cannot hold.
    fn check_size(&self, settings: &specula_render::Settings) -> Result<(), GpuError> {
        settings
            .validate()
            .map_err(|e| GpuError::Unsupported(e.to_string()))?;
        let limit = self.gpu.device.limits().max_texture_dimension_2d;
        let largest = settings.width.max(settings.height) * settings.samples;
        if largest > limit {
            return Err(GpuError::Unsupported(format!(
                "{largest} samples per side exceed this adapter's largest texture side, {limit}"
            )));
        }
        Ok(())
    }

    /// Renders `scene` and reads the image back.
    pub fn render(&self, scene: &Scene) -> Result<Image, GpuError> {
        let settings = &scene.settings;
        self.check_size(settings)?;
        let s = settings.samples;
        let (width, height) = (settings.width * s, settings.height * s);
        let row_bytes = (width * 16).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let readback = self
            .gpu
            .checked(|| self.draw(scene, width, height, Some(row_bytes)))?
            .ok_or_else(|| GpuError::Operation("no read-back buffer".into()))?;
        let bytes = self.gpu.read_buffer(&readback)?;
        Ok(downsample(
            &bytes,
            row_bytes as usize,
            settings.width,
            settings.height,
            s,
        ))
    }

    /// Draws `scene` (uploading its buffers) and waits for the GPU, without reading the image
    /// back: the time a frame takes, for benchmarks.
    pub fn time_frame(&self, scene: &Scene) -> Result<std::time::Duration, GpuError> {
        let settings = &scene.settings;
        self.check_size(settings)?;
        let started = std::time::Instant::now();
        let (width, height) = (
            settings.width * settings.samples,
            settings.height * settings.samples,
        );
        self.gpu.checked(|| self.draw(scene, width, height, None))?;
        self.gpu
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Operation(e.to_string()))?;
        Ok(started.elapsed())
    }

    /// Records and submits the frame; with `row_bytes`, also copies the image to a read-back
    /// buffer with rows of that many bytes.
    fn draw(
        &self,
        scene: &Scene,
        width: u32,
        height: u32,
        row_bytes: Option<u32>,
    ) -> Option<wgpu::Buffer> {
        let device = &self.gpu.device;
        let pipeline = if scene.settings.cull_back_faces {
            &self.culled
        } else {
            &self.unculled
        };
        let camera = &scene.camera;
        let frame = FrameBlock {
            view_projection: camera
                .view_projection(width as f32 / height as f32)
                .to_cols_array_2d(),
            eye: camera.eye().to_array(),
            orthographic: u32::from(matches!(
                camera.projection(),
                specula_render::Projection::Orthographic { .. }
            )),
            backwards: camera.backwards().to_array(),
            light_count: scene.lights.len() as u32,
            ambient: scene.ambient.to_array(),
            shading: match scene.settings.shading {
                Shading::Flat => 0,
                Shading::Gouraud => 1,
                Shading::Phong => 2,
            },
        };
        let mut lights: Vec<LightBlock> = scene.lights.iter().map(LightBlock::new).collect();
        if lights.is_empty() {
            // A storage binding cannot be empty; light_count = 0 keeps the shader off it.
            lights.push(LightBlock::default());
        }
        let frame_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("frame"),
            contents: bytemuck::bytes_of(&frame),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let light_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("lights"),
            contents: bytemuck::cast_slice(&lights),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let globals = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("globals"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: frame_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: light_buffer.as_entire_binding(),
                },
            ],
        });
        let objects: Vec<ObjectBuffers> = scene
            .objects
            .iter()
            .map(|object| {
                let material = MaterialBlock::new(&object.material, scene.settings.model);
                let material_buffer =
                    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("material"),
                        contents: bytemuck::bytes_of(&material),
                        usage: wgpu::BufferUsages::UNIFORM,
                    });
                let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("material"),
                    layout: &pipeline.get_bind_group_layout(1),
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: material_buffer.as_entire_binding(),
                    }],
                });
                object_buffers(device, &object.mesh, scene.settings.shading, bind_group)
            })
            .collect();
        let target = |format, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some("target"),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let colour = target(
            COLOUR_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let depth = target(DEPTH_FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT);
        let readback = row_bytes.map(|row_bytes| {
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("image readback"),
                size: u64::from(row_bytes) * u64::from(height),
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            (buffer, row_bytes)
        });
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        {
            let colour_view = colour.create_view(&wgpu::TextureViewDescriptor::default());
            let depth_view = depth.create_view(&wgpu::TextureViewDescriptor::default());
            let background = scene.settings.background.as_dvec3();
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("scene"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &colour_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color {
                            r: background.x,
                            g: background.y,
                            b: background.z,
                            a: 1.0,
                        }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                ..wgpu::RenderPassDescriptor::default()
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &globals, &[]);
            for object in &objects {
                pass.set_bind_group(1, &object.material, &[]);
                pass.set_vertex_buffer(0, object.vertices.slice(..));
                match &object.indices {
                    Some((indices, count)) => {
                        pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
                        pass.draw_indexed(0..*count, 0, 0..1);
                    }
                    None => pass.draw(0..object.vertex_count, 0..1),
                }
            }
        }
        if let Some((buffer, row_bytes)) = &readback {
            encoder.copy_texture_to_buffer(
                colour.as_image_copy(),
                wgpu::TexelCopyBufferInfo {
                    buffer,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(*row_bytes),
                        rows_per_image: Some(height),
                    },
                },
                wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
            );
        }
        self.gpu.queue.submit([encoder.finish()]);
        readback.map(|(buffer, _)| buffer)
    }
}

/// Vertex (and index) buffers: indexed for Gouraud and Phong; for flat shading each triangle
/// gets its own three vertices carrying the face normal and the centroid.
fn object_buffers(
    device: &wgpu::Device,
    mesh: &specula_render::Mesh,
    shading: Shading,
    material: wgpu::BindGroup,
) -> ObjectBuffers {
    let mut vertices: Vec<f32> = Vec::new();
    let mut indices = None;
    if shading == Shading::Flat {
        for triangle in mesh.triangles() {
            let [a, b, c] = triangle.map(|i| mesh.positions()[i as usize]);
            let Some(face) = (b - a).cross(c - a).try_normalize() else {
                continue;
            };
            let centroid = (a + b + c) / 3.0;
            for p in [a, b, c] {
                vertices.extend(
                    p.to_array()
                        .into_iter()
                        .chain(face.to_array())
                        .chain(centroid.to_array()),
                );
            }
        }
    } else {
        for (p, n) in mesh.positions().iter().zip(mesh.normals()) {
            vertices.extend(
                p.to_array()
                    .into_iter()
                    .chain(n.to_array())
                    .chain(p.to_array()),
            );
        }
        let flat: Vec<u32> = mesh.triangles().iter().flatten().copied().collect();
        if !flat.is_empty() {
            let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("indices"),
                contents: bytemuck::cast_slice(&flat),
                usage: wgpu::BufferUsages::INDEX,
            });
            indices = Some((buffer, flat.len() as u32));
        }
    }
    if vertices.is_empty() {
        // wgpu refuses empty buffers; a lone vertex and no triangles draw nothing.
        vertices.resize(VERTEX_FLOATS, 0.0);
        indices = None;
    }
    let vertex_count = if shading == Shading::Flat {
        (vertices.len() / VERTEX_FLOATS) as u32 / 3 * 3
    } else {
        0
    };
    ObjectBuffers {
        vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("vertices"),
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX,
        }),
        indices,
        vertex_count,
        material,
    }
}

/// Box-filters the `samples x samples` blocks of the read-back `Rgba32Float` rows.
fn downsample(bytes: &[u8], row_bytes: usize, width: u32, height: u32, samples: u32) -> Image {
    let texel = |x: u32, y: u32| {
        let offset = y as usize * row_bytes + x as usize * 16;
        let channel = |k: usize| {
            let at = offset + 4 * k;
            f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
        };
        Vec3::new(channel(0), channel(1), channel(2))
    };
    let scale = 1.0 / (samples * samples) as f32;
    let mut image = Image::new(width, height, Vec3::ZERO);
    for y in 0..height {
        for x in 0..width {
            let mut sum = Vec3::ZERO;
            for sy in 0..samples {
                for sx in 0..samples {
                    sum += texel(x * samples + sx, y * samples + sy);
                }
            }
            image.set(x, y, sum * scale);
        }
    }
    image
}
