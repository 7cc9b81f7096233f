//! Finding a GPU: the adapter wgpu offers (a real GPU, or Mesa's lavapipe on the CPU), and a
//! device on it. Every failure is a [`GpuError`] with advice, never a panic.

use thiserror::Error;

/// Why the GPU pipeline cannot run.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum GpuError {
    /// wgpu found no adapter at all.
    #[error(
        "no GPU adapter found ({0}); on a machine without a GPU install Mesa's lavapipe \
        (Debian/Ubuntu: apt-get install mesa-vulkan-drivers), or use the CPU backend"
    )]
    NoAdapter(String),
    /// The adapter refused a device.
    #[error("the GPU adapter {adapter} refused a device: {message}")]
    Device {
        /// The adapter's name.
        adapter: String,
        /// wgpu's reason.
        message: String,
    },
    /// A GPU operation failed (validation, out of memory, a lost device, a failed read-back).
    #[error("GPU error: {0}")]
    Operation(String),
    /// The request is beyond what the adapter allows.
    #[error("{0}")]
    Unsupported(String),
}

/// A device and its queue, with the adapter's description.
#[derive(Debug)]
pub struct Gpu {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
}

impl Gpu {
    /// The first adapter wgpu offers (high performance preferred), and a device on it.
    pub fn new() -> Result<Self, GpuError> {
        // The primary backends (Vulkan, Metal, DX12): lavapipe is a Vulkan driver, and probing
        // GL without a display only prints noise. WGPU_BACKEND overrides.
        let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        descriptor.backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY);
        let instance = wgpu::Instance::new(descriptor);
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..wgpu::RequestAdapterOptions::default()
        }))
        .map_err(|e| GpuError::NoAdapter(e.to_string()))?;
        let info = adapter.get_info();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("specula"),
            // Timestamps let frame benchmarks time the pass on the GPU's own clock.
            required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
            required_limits: adapter.limits(),
            ..wgpu::DeviceDescriptor::default()
        }))
        .map_err(|e| GpuError::Device {
            adapter: info.name.clone(),
            message: e.to_string(),
        })?;
        Ok(Self {
            device,
            queue,
            info,
        })
    }

    /// The adapter's name and driver, e.g. `llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan, Mesa
    /// 22.3.6)`.
    #[must_use]
    pub fn adapter_name(&self) -> String {
        let info = &self.info;
        let driver = [info.driver.as_str(), info.driver_info.as_str()]
            .into_iter()
            .filter(|s| !s.is_empty())
            .collect::<Vec<_>>()
            .join(" ");
        format!("{} ({:?}, {})", info.name, info.backend, driver)
    }

    /// Whether the adapter is a rasterizer in software (lavapipe, SwiftShader, WARP): its
    /// frame times are the CPU's, not a GPU's.
    #[must_use]
    pub fn is_software(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// Runs `work` and waits for the GPU, turning validation and memory errors into a
    /// [`GpuError`] instead of wgpu's default panic.
    pub(crate) fn checked<T>(&self, work: impl FnOnce() -> T) -> Result<T, GpuError> {
        let scopes = [
            self.device.push_error_scope(wgpu::ErrorFilter::Validation),
            self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory),
        ];
        let value = work();
        for scope in scopes.into_iter().rev() {
            if let Some(error) = pollster::block_on(scope.pop()) {
                return Err(GpuError::Operation(error.to_string()));
            }
        }
        Ok(value)
    }

    /// Copies `buffer` (created with `MAP_READ`) to memory once the queue is done.
    pub(crate) fn read_buffer(&self, buffer: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
        let slice = buffer.slice(..);
        let (sender, receiver) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |result| {
            let _ = sender.send(result);
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Operation(e.to_string()))?;
        receiver
            .recv()
            .map_err(|e| GpuError::Operation(e.to_string()))?
            .map_err(|e| GpuError::Operation(e.to_string()))?;
        let bytes = slice
            .get_mapped_range()
            .map_err(|e| GpuError::Operation(e.to_string()))?
            .to_vec();
        buffer.unmap();
        Ok(bytes)
    }
}
