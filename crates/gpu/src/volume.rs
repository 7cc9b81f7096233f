//! Direct volume rendering on the GPU: `shaders/volume.wgsl`, one compute invocation per
//! pixel, marching the rays the CPU's [`DvrPlan`] fixes through the volume's value and world
//! gradient per voxel ([`PreparedVolume`], the CPU marcher's field) uploaded as an
//! `rgba32float` 3D texture.

use std::sync::{Arc, Mutex, PoisonError};

use bytemuck::{Pod, Zeroable};
use specula::Lobe;
use specula_render::Image;
use specula_volume::dvr::{DvrPlan, DvrSettings, Lighting};
use specula_volume::march::{Classification, PreparedVolume};
use specula_volume::transfer::TransferFunction;
use specula_volume::Volume;
use wgpu::util::DeviceExt;

use crate::context::{Gpu, GpuError};
use crate::uniforms::{geometry_id, LobeBlock};
use crate::wgsl::{self, FunctionKey};

/// `struct Params` of volume.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct Params {
    eye: [f32; 4],
    forward: [f32; 4],
    right: [f32; 4],
    up: [f32; 4],
    to_index: [[f32; 4]; 3],
    origin: [f32; 4],
    light: [f32; 4],
    weights: [f32; 4],
    background: [f32; 4],
    size: [u32; 4],
    dims: [u32; 4],
    bricks: [u32; 4],
    classify: [f32; 4],
}

/// `struct Highlight` of volume.wgsl (48 bytes): a lobe an image shows and its scale.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct HighlightBlock {
    lobe: LobeBlock,
    /// `ks N(n)` in `x`.
    scale: [f32; 4],
}

/// The compiled ray marcher: one pipeline per list of highlights' lobes, compiled when
/// first asked for ([`wgsl::volume_module`]).
#[derive(Debug)]
pub struct GpuVolumeRenderer<'gpu> {
    gpu: &'gpu Gpu,
    pipelines: Mutex<Vec<(Vec<FunctionKey>, Arc<wgpu::ComputePipeline>)>>,
}

fn with_w(v: glam::Vec3, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

impl<'gpu> GpuVolumeRenderer<'gpu> {
    /// The ray marcher for `gpu`; each list of lobes' pipeline is compiled when first used
    /// (or by [`GpuVolumeRenderer::prepare`]).
    #[must_use]
    pub fn new(gpu: &'gpu Gpu) -> Self {
        Self {
            gpu,
            pipelines: Mutex::new(Vec::new()),
        }
    }

    /// Compiles beforehand the pipelines that [`GpuVolumeRenderer::render_lobes`] of `lobes`
    /// uses (its marches of up to [`wgsl::MAX_HIGHLIGHTS`] lobes), so that a timed frame
    /// does not include compiling them; [`GpuVolumeRenderer::render`]'s for a lobe is that of
    /// a list of one.
    ///
    /// # Errors
    /// When the driver refuses the shader.
    pub fn prepare(&self, lobes: &[Lobe]) -> Result<(), GpuError> {
        let keys: Vec<FunctionKey> = lobes.iter().map(FunctionKey::of).collect();
        for some in keys.chunks(wgsl::MAX_HIGHLIGHTS) {
            self.pipeline(some)?;
        }
        Ok(())
    }

    /// The pipeline whose images' highlights are `keys`' lobes, in order.
    fn pipeline(&self, keys: &[FunctionKey]) -> Result<Arc<wgpu::ComputePipeline>, GpuError> {
        let compiled = || {
            self.pipelines
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
        };
        if let Some((_, pipeline)) = compiled().iter().find(|(known, _)| known == keys) {
            return Ok(Arc::clone(pipeline));
        }
        let source = wgsl::volume_module(keys);
        let device = &self.gpu.device;
        let pipeline = Arc::new(self.gpu.checked(|| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("specula volume"),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("specula volume"),
                layout: None,
                module: &module,
                entry_point: Some("march"),
                compilation_options: wgpu::PipelineCompilationOptions::default(),
                cache: None,
            })
        })?);
        // Another thread may have compiled the same list meanwhile: the first one is kept.
        let mut compiled = compiled();
        if let Some((_, known)) = compiled.iter().find(|(known, _)| known == keys) {
            return Ok(Arc::clone(known));
        }
        compiled.push((keys.to_vec(), Arc::clone(&pipeline)));
        Ok(pipeline)
    }

    /// Renders as [`specula_volume::dvr::render_dvr`] does.
    pub fn render(
        &self,
        volume: &Volume,
        transfer: &TransferFunction,
        settings: &DvrSettings,
    ) -> Result<Image, GpuError> {
        let plan = DvrPlan::new(volume, settings).map_err(|e| GpuError::Unsupported(e.0))?;
        let lobes: Vec<Lobe> = plan
            .lighting
            .iter()
            .map(|lighting| lighting.shading.lobe)
            .collect();
        self.march(volume, transfer, settings, &plan, &lobes)?
            .pop()
            .ok_or_else(|| GpuError::Unsupported("the march drew no image".into()))
    }

    /// [`GpuVolumeRenderer::render`] once for each of `lobes`, the settings' shading with its
    /// lobe replaced by each in turn, as
    /// [`specula_volume::dvr::render_dvr_lobes`] does: up to 16 images a march,
    /// the samples' colours and opacities computed once for them all, and each image the one
    /// its lobe alone draws (one march's arithmetic, tested).
    ///
    /// # Errors
    /// As [`GpuVolumeRenderer::render`]; and when the settings are unshaded.
    pub fn render_lobes(
        &self,
        volume: &Volume,
        transfer: &TransferFunction,
        settings: &DvrSettings,
        lobes: &[Lobe],
    ) -> Result<Vec<Image>, GpuError> {
        let plan = DvrPlan::new(volume, settings).map_err(|e| GpuError::Unsupported(e.0))?;
        if plan.lighting.is_none() {
            return Err(GpuError::Unsupported(
                "an unshaded render has no lobe to vary: give it a shading".into(),
            ));
        }
        let image_bytes = u64::from(settings.width) * u64::from(settings.height) * 16;
        let fit = self.gpu.device.limits().max_storage_buffer_binding_size / image_bytes.max(1);
        let per_march = (fit as usize).clamp(1, wgsl::MAX_HIGHLIGHTS);
        let mut images = Vec::with_capacity(lobes.len());
        for some in lobes.chunks(per_march) {
            images.extend(self.march(volume, transfer, settings, &plan, some)?);
        }
        Ok(images)
    }

    /// One march drawing an image per lobe's highlight (one image when there is none:
    /// unshaded).
    fn march(
        &self,
        volume: &Volume,
        transfer: &TransferFunction,
        settings: &DvrSettings,
        plan: &DvrPlan,
        lobes: &[Lobe],
    ) -> Result<Vec<Image>, GpuError> {
        let highlights: Vec<HighlightBlock> = match &plan.lighting {
            Some(lighting) => lobes.iter().map(|lobe| highlight(lighting, lobe)).collect(),
            None => Vec::new(),
        };
        let keys: Vec<FunctionKey> = lobes
            .iter()
            .take(highlights.len())
            .map(FunctionKey::of)
            .collect();
        let pipeline = self.pipeline(&keys)?;
        let device = &self.gpu.device;
        let limits = device.limits();
        let dims = volume.dims();
        let side = dims.iter().copied().max().unwrap_or(0);
        if side > limits.max_texture_dimension_3d as usize {
            return Err(GpuError::Unsupported(format!(
                "a volume {side} voxels wide; this GPU's 3D textures hold at most {} per side (use \
                    --backend cpu)",
                limits.max_texture_dimension_3d
            )));
        }
        let (width, height) = (settings.width, settings.height);
        let images = highlights.len().max(1);
        let image_bytes = u64::from(width) * u64::from(height) * 16;
        let output_bytes = image_bytes * images as u64;
        if output_bytes > limits.max_storage_buffer_binding_size {
            return Err(GpuError::Unsupported(format!(
                "{images} image(s) of {width} x {height} need {output_bytes} bytes; this GPU binds \
                    at most {} (use --backend cpu or a smaller image)",
                limits.max_storage_buffer_binding_size
            )));
        }
        let prepared = PreparedVolume::new(volume);
        let classification = Classification::new(&prepared, transfer);
        let clearance: Vec<u32> = classification
            .clearance()
            .iter()
            .map(|&c| u32::from(c))
            .collect();
        let tables = classification.tables();
        let pieces: Vec<[f32; 12]> = tables
            .pieces
            .iter()
            .map(|&(start, [s0, s1, s2, s3], [d0, d1, d2, d3])| {
                [start, 0.0, 0.0, 0.0, s0, s1, s2, s3, d0, d1, d2, d3]
            })
            .collect();
        let mut params = params(volume, &prepared, transfer, settings, plan);
        params.dims[3] = images as u32;
        params.classify = [
            tables.lowest,
            tables.per_entry,
            (tables.first_piece.len() - 1) as f32,
            0.0,
        ];
        let readback = self.gpu.checked(|| {
            let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("volume params"),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let storage = |label: &str, contents: &[u8]| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage: wgpu::BufferUsages::STORAGE,
                })
            };
            let pieces = storage("transfer function pieces", bytemuck::cast_slice(&pieces));
            let first_piece = storage(
                "classification table",
                bytemuck::cast_slice(&tables.first_piece),
            );
            let bounds = storage(
                "transfer function bounds",
                bytemuck::cast_slice(&tables.bounds),
            );
            let clearance = storage("brick clearance", bytemuck::cast_slice(&clearance));
            // An unshaded march reads no highlight, but a binding holds at least one.
            let none = [HighlightBlock::zeroed()];
            let highlights = storage(
                "highlights",
                bytemuck::cast_slice(if highlights.is_empty() {
                    &none
                } else {
                    &highlights
                }),
            );
            let extent = wgpu::Extent3d {
                width: dims[0] as u32,
                height: dims[1] as u32,
                depth_or_array_layers: dims[2] as u32,
            };
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("volume"),
                size: extent,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D3,
                format: wgpu::TextureFormat::Rgba32Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            });
            self.gpu.queue.write_texture(
                texture.as_image_copy(),
                bytemuck::cast_slice(&prepared.voxels()),
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(16 * dims[0] as u32),
                    rows_per_image: Some(dims[1] as u32),
                },
                extent,
            );
            let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
            let output = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("volume pixels"),
                size: output_bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let readback = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("volume pixels readback"),
                size: output_bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("volume"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: params.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: pieces.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::TextureView(&view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 3,
                        resource: output.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 4,
                        resource: clearance.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 5,
                        resource: first_piece.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 6,
                        resource: bounds.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 7,
                        resource: highlights.as_entire_binding(),
                    },
                ],
            });
            let mut encoder =
                device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
                pass.set_pipeline(&pipeline);
                pass.set_bind_group(0, &bind_group, &[]);
                pass.dispatch_workgroups(width.div_ceil(8), height.div_ceil(8), 1);
            }
            encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, output_bytes);
            self.gpu.queue.submit([encoder.finish()]);
            readback
        })?;
        let bytes = self.gpu.read_buffer(&readback)?;
        bytes
            .chunks_exact(image_bytes as usize)
            .map(|image| {
                let pixels = image
                    .chunks_exact(16)
                    .map(|b| {
                        let channel = |c: usize| {
                            f32::from_le_bytes([b[4 * c], b[4 * c + 1], b[4 * c + 2], b[4 * c + 3]])
                        };
                        glam::Vec3::new(channel(0), channel(1), channel(2))
                    })
                    .collect();
                Image::from_pixels(width, height, pixels)
                    .ok_or_else(|| GpuError::Unsupported("the image could not be assembled".into()))
            })
            .collect()
    }
}

/// The block of `lobe`'s highlight under `lighting`.
fn highlight(lighting: &Lighting, lobe: &Lobe) -> HighlightBlock {
    HighlightBlock {
        lobe: LobeBlock::new(lobe),
        scale: [lighting.highlight_scale(lobe), 0.0, 0.0, 0.0],
    }
}

fn params(
    volume: &Volume,
    prepared: &PreparedVolume,
    transfer: &TransferFunction,
    settings: &DvrSettings,
    plan: &DvrPlan,
) -> Params {
    let camera = &plan.camera;
    let to_index = volume.to_index();
    let [nx, ny, nz] = volume.dims();
    let (light, weights, gradient_reference, geometry) = match &plan.lighting {
        Some(lighting) => {
            let shading = &lighting.shading;
            // w: what a sample with no gradient keeps of its colour.
            let flat = if shading.ambient_where_flat {
                shading.ka
            } else {
                1.0
            };
            (
                with_w(lighting.light, flat),
                [shading.ka, shading.kd, shading.ks, 1.0],
                lighting.gradient_reference,
                geometry_id(shading.geometry),
            )
        }
        None => (with_w(glam::Vec3::Z, 1.0), [0.0; 4], 1.0, 0),
    };
    Params {
        eye: with_w(camera.eye, camera.half_height),
        forward: with_w(camera.forward, if camera.parallel { 1.0 } else { 0.0 }),
        right: with_w(camera.right, plan.step),
        up: with_w(camera.up, settings.opacity_cutoff),
        to_index: [
            with_w(to_index.x_axis, 0.0),
            with_w(to_index.y_axis, 0.0),
            with_w(to_index.z_axis, 0.0),
        ],
        origin: with_w(volume.origin(), gradient_reference),
        light,
        weights,
        background: with_w(settings.background, 0.0),
        size: [
            settings.width,
            settings.height,
            transfer.points().len() as u32,
            geometry,
        ],
        dims: [nx as u32, ny as u32, nz as u32, 0],
        bricks: {
            let [bx, by, bz] = prepared.bricks();
            [bx as u32, by as u32, bz as u32, 0]
        },
        classify: [0.0; 4],
    }
}

#[cfg(test)]
mod tests {
    use specula::{Exponent, LobeKind};

    use super::*;

    /// `Params` and `Highlight` have the sizes WGSL's layout rules give them.
    #[test]
    fn blocks_match_the_wgsl_layout() {
        let wgsl_size = crate::uniforms::wgsl_size_of(&wgsl::volume_module(&[FunctionKey::of(
            &Lobe::new(LobeKind::Pow, Exponent::new(8.0)),
        )]));
        assert_eq!(wgsl_size("Params"), size_of::<Params>());
        assert_eq!(wgsl_size("Highlight"), size_of::<HighlightBlock>());
    }
}
