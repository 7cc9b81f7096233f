//! A scene uploaded once and drawn as often as asked: what a renderer keeps between frames,
//! and what a frame benchmark must not time.
//!
//! [`GpuFrame`] holds the scene's buffers, bind groups, render targets and read-back buffer.
//! Each [`GpuFrame::draw`] records one pass (and, when asked, the copy to the read-back
//! buffer), submits it and waits, so timing it measures the GPU's frame, not the set-up.
//! Where the adapter has timestamp queries, the pass itself is timed on the GPU too.

use std::sync::Arc;
use std::time::{Duration, Instant};

use specula_render::{Image, Projection, Scene, Shading};
use wgpu::util::DeviceExt;

use crate::context::{Gpu, GpuError};
use crate::render::GpuRenderer;
use crate::render::{downsample, COLOUR_FORMAT, DEPTH_FORMAT, VERTEX_FLOATS};
use crate::uniforms::{FrameBlock, LightBlock, MaterialBlock};

/// One object's geometry as the shaders take it.
struct ObjectBuffers {
    vertices: wgpu::Buffer,
    indices: Option<(wgpu::Buffer, u32)>,
    vertex_count: u32,
    material: wgpu::BindGroup,
}

/// Start and end timestamps of the scene pass, written by the GPU.
struct PassTimer {
    queries: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    readback: wgpu::Buffer,
    /// Nanoseconds per timestamp tick.
    period: f32,
}

/// A scene on the GPU, ready to draw.
pub struct GpuFrame<'r> {
    gpu: &'r Gpu,
    pipeline: Arc<wgpu::RenderPipeline>,
    globals: wgpu::BindGroup,
    objects: Vec<ObjectBuffers>,
    colour: wgpu::Texture,
    depth: wgpu::Texture,
    readback: wgpu::Buffer,
    row_bytes: u32,
    /// The target's size in samples, and samples per pixel side.
    size: (u32, u32, u32),
    background: wgpu::Color,
    timer: Option<PassTimer>,
}

/// How long one frame took.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameTime {
    /// From recording the commands to the GPU being done (and the image mapped, with
    /// read-back), on the host's clock.
    pub wall: Duration,
    /// The scene pass alone, by the GPU's timestamps, where the adapter has them.
    pub pass: Option<Duration>,
}

impl GpuRenderer<'_> {
    /// Uploads `scene`: buffers, materials, render targets and the read-back buffer; compiles
    /// the pipeline for the scene's lobes the first time a scene holds them (a driver's
    /// refusal of the shader is then this call's error).
    pub fn prepare(&self, scene: &Scene) -> Result<GpuFrame<'_>, GpuError> {
        let settings = &scene.settings;
        self.check_size(settings)?;
        let samples = settings.samples;
        let (width, height) = (settings.width * samples, settings.height * samples);
        let materials: Vec<MaterialBlock> = scene
            .objects
            .iter()
            .map(|object| MaterialBlock::new(&object.material, settings.model))
            .collect();
        let mut keys: Vec<_> = materials.iter().map(MaterialBlock::lobe_key).collect();
        keys.sort_unstable();
        keys.dedup();
        let pipeline = self.pipeline(&keys, settings.cull_back_faces)?;
        self.gpu.checked(|| {
            let device = &self.gpu.device;
            let row_bytes = (width * 16).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
            let background = settings.background.as_dvec3();
            GpuFrame {
                gpu: self.gpu,
                globals: globals(device, &pipeline, scene, width, height),
                objects: scene
                    .objects
                    .iter()
                    .zip(&materials)
                    .map(|(object, material)| {
                        let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                            label: Some("material"),
                            contents: bytemuck::bytes_of(material),
                            usage: wgpu::BufferUsages::UNIFORM,
                        });
                        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                            label: Some("material"),
                            layout: &pipeline.get_bind_group_layout(1),
                            entries: &[wgpu::BindGroupEntry {
                                binding: 0,
                                resource: buffer.as_entire_binding(),
                            }],
                        });
                        object_buffers(device, &object.mesh, settings.shading, bind_group)
                    })
                    .collect(),
                colour: target(
                    device,
                    (width, height),
                    COLOUR_FORMAT,
                    wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                ),
                depth: target(
                    device,
                    (width, height),
                    DEPTH_FORMAT,
                    wgpu::TextureUsages::RENDER_ATTACHMENT,
                ),
                readback: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("image readback"),
                    size: u64::from(row_bytes) * u64::from(height),
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                row_bytes,
                size: (width, height, samples),
                background: wgpu::Color {
                    r: background.x,
                    g: background.y,
                    b: background.z,
                    a: 1.0,
                },
                timer: pass_timer(self.gpu),
                pipeline,
            }
        })
    }
}

impl GpuFrame<'_> {
    /// Draws the frame and waits for the GPU; with `read_back`, also copies the image out and
    /// maps it, as a renderer that shows or saves every frame must.
    pub fn draw(&self, read_back: bool) -> Result<FrameTime, GpuError> {
        let started = Instant::now();
        self.gpu.checked(|| self.submit(read_back))?;
        if read_back {
            self.gpu.read_buffer(&self.readback)?;
        } else {
            self.gpu
                .device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| GpuError::Operation(e.to_string()))?;
        }
        let wall = started.elapsed();
        let pass = match &self.timer {
            Some(timer) => Some(timer.elapsed(self.gpu)?),
            None => None,
        };
        Ok(FrameTime { wall, pass })
    }

    /// Draws the frame and returns the image, box-filtered to the scene's size.
    pub fn image(&self) -> Result<Image, GpuError> {
        self.gpu.checked(|| self.submit(true))?;
        let bytes = self.gpu.read_buffer(&self.readback)?;
        let (width, height, samples) = self.size;
        Ok(downsample(
            &bytes,
            self.row_bytes as usize,
            width / samples,
            height / samples,
            samples,
        ))
    }

    /// Records the pass (and the copy to the read-back buffer) and submits it.
    fn submit(&self, read_back: bool) {
        let device = &self.gpu.device;
        let (width, height, _) = self.size;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        {
            let colour_view = self
                .colour
                .create_view(&wgpu::TextureViewDescriptor::default());
            let depth_view = self
                .depth
                .create_view(&wgpu::TextureViewDescriptor::default());
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("scene"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &colour_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(self.background),
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
                timestamp_writes: self.timer.as_ref().map(|timer| {
                    wgpu::RenderPassTimestampWrites {
                        query_set: &timer.queries,
                        beginning_of_pass_write_index: Some(0),
                        end_of_pass_write_index: Some(1),
                    }
                }),
                ..wgpu::RenderPassDescriptor::default()
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.globals, &[]);
            for object in &self.objects {
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
        if let Some(timer) = &self.timer {
            encoder.resolve_query_set(&timer.queries, 0..2, &timer.resolved, 0);
            encoder.copy_buffer_to_buffer(&timer.resolved, 0, &timer.readback, 0, 16);
        }
        if read_back {
            encoder.copy_texture_to_buffer(
                self.colour.as_image_copy(),
                wgpu::TexelCopyBufferInfo {
                    buffer: &self.readback,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(self.row_bytes),
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
    }
}

impl PassTimer {
    /// The last pass's duration (read after the frame's wait, outside its wall time).
    fn elapsed(&self, gpu: &Gpu) -> Result<Duration, GpuError> {
        let bytes = gpu.read_buffer(&self.readback)?;
        let tick = |at: usize| {
            let mut word = [0; 8];
            word.copy_from_slice(&bytes[at..at + 8]);
            u64::from_le_bytes(word)
        };
        let ticks = tick(8).saturating_sub(tick(0));
        Ok(Duration::from_nanos(
            (ticks as f64 * f64::from(self.period)) as u64,
        ))
    }
}

/// Timestamp queries around the pass, where the device has them.
fn pass_timer(gpu: &Gpu) -> Option<PassTimer> {
    let device = &gpu.device;
    if !device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
        return None;
    }
    let buffer = |label, usage| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: 16,
            usage,
            mapped_at_creation: false,
        })
    };
    Some(PassTimer {
        queries: device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("pass timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: 2,
        }),
        resolved: buffer(
            "pass timestamps",
            wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        ),
        readback: buffer(
            "pass timestamps readback",
            wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        ),
        period: gpu.queue.get_timestamp_period(),
    })
}

/// The camera and lights, bound once per frame.
fn globals(
    device: &wgpu::Device,
    pipeline: &wgpu::RenderPipeline,
    scene: &Scene,
    width: u32,
    height: u32,
) -> wgpu::BindGroup {
    let camera = &scene.camera;
    let frame = FrameBlock {
        view_projection: camera
            .view_projection(width as f32 / height as f32)
            .to_cols_array_2d(),
        eye: camera.eye().to_array(),
        orthographic: u32::from(matches!(
            camera.projection(),
            Projection::Orthographic { .. }
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
    device.create_bind_group(&wgpu::BindGroupDescriptor {
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
    })
}

fn target(
    device: &wgpu::Device,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
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
