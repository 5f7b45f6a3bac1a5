//! The one wgpu device of the process: adapter, device and queue are made on
//! first use and kept (a `OnceLock`), with the compiled pipelines, because
//! creating a device and compiling shaders costs far more than a small map.

use crate::error::{Error, Result};
use std::sync::OnceLock;

/// What the adapter says about itself.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GpuInfo {
    pub name: String,
    /// The graphics API wgpu drives it through ("vulkan", "metal" or "dx12").
    pub backend: String,
    /// "discrete_gpu", "integrated_gpu", "virtual_gpu", "cpu" or "other".
    pub device_type: String,
    pub driver: String,
    /// A software renderer (lavapipe, llvmpipe, SwiftShader): correct but
    /// slower than the CPU backend; `backend="auto"` does not pick it.
    pub software: bool,
}

/// The device, its queue and what it can do.
pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: GpuInfo,
    /// Whether compute passes can carry timestamp queries (per-stage device times).
    pub timestamps: bool,
    /// The largest storage buffer binding, in bytes.
    pub max_storage_binding: u64,
}

/// The environment variable that hides every adapter when set to "off" (or
/// "0"): what a machine without a GPU looks like, for tests and for users who
/// want `backend="auto"` to stay on the CPU. Read on every call.
pub const ENV_SWITCH: &str = "SOFTSHADOW_GPU";

fn disabled_by_env() -> bool {
    matches!(
        std::env::var(ENV_SWITCH).as_deref().map(str::trim),
        Ok("off") | Ok("0") | Ok("OFF") | Ok("false")
    )
}

fn device_type_name(t: wgpu::DeviceType) -> &'static str {
    match t {
        wgpu::DeviceType::DiscreteGpu => "discrete_gpu",
        wgpu::DeviceType::IntegratedGpu => "integrated_gpu",
        wgpu::DeviceType::VirtualGpu => "virtual_gpu",
        wgpu::DeviceType::Cpu => "cpu",
        wgpu::DeviceType::Other => "other",
    }
}

/// Preference among adapters: real GPUs first, software renderers last.
fn rank(t: wgpu::DeviceType) -> u32 {
    match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    }
}

/// The graphics APIs asked for. wgpu skips those not compiled in: Cargo.toml
/// turns on Metal only for Apple targets and DX12 only for Windows, so on
/// Linux this is Vulkan alone.
const BACKENDS: wgpu::Backends = wgpu::Backends::VULKAN
    .union(wgpu::Backends::METAL)
    .union(wgpu::Backends::DX12);

fn open() -> std::result::Result<Gpu, String> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
        backends: BACKENDS,
        ..wgpu::InstanceDescriptor::new_without_display_handle()
    });
    let adapters = pollster::block_on(instance.enumerate_adapters(BACKENDS));
    // Among adapters of the same kind (one GPU seen through Vulkan and DX12
    // on Windows) Vulkan first: it is the API the tests run.
    let adapter = adapters
        .into_iter()
        .min_by_key(|a| {
            let i = a.get_info();
            (rank(i.device_type), i.backend != wgpu::Backend::Vulkan)
        })
        .ok_or_else(|| {
            "no GPU adapter found through Vulkan, Metal or DX12 (install a GPU \
             driver, or on Linux Mesa's lavapipe: apt-get install \
             mesa-vulkan-drivers libvulkan1)"
                .to_string()
        })?;
    let ai = adapter.get_info();
    let timestamps = adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY);
    let features = if timestamps {
        wgpu::Features::TIMESTAMP_QUERY
    } else {
        wgpu::Features::empty()
    };
    let limits = adapter.limits();
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("softshadow"),
        required_features: features,
        required_limits: limits.clone(),
        ..Default::default()
    }))
    .map_err(|e| format!("the adapter {:?} refused a device: {e}", ai.name))?;
    let info = GpuInfo {
        name: ai.name.clone(),
        backend: ai.backend.to_string(),
        device_type: device_type_name(ai.device_type).to_string(),
        driver: format!("{} {}", ai.driver, ai.driver_info)
            .trim()
            .to_string(),
        software: ai.device_type == wgpu::DeviceType::Cpu,
    };
    Ok(Gpu {
        device,
        queue,
        info,
        timestamps,
        max_storage_binding: limits.max_storage_buffer_binding_size as u64,
    })
}

static GPU: OnceLock<std::result::Result<Gpu, String>> = OnceLock::new();

/// The process's device, opened on first use; `GpuUnavailable` when there is
/// no adapter or `SOFTSHADOW_GPU=off`.
pub fn gpu() -> Result<&'static Gpu> {
    if disabled_by_env() {
        return Err(Error::gpu_unavailable(format!(
            "the GPU is switched off by {ENV_SWITCH}={}",
            std::env::var(ENV_SWITCH).unwrap_or_default()
        )));
    }
    GPU.get_or_init(open)
        .as_ref()
        .map_err(|m| Error::gpu_unavailable(m.clone()))
}
