//! Small helpers every GPU stage uses: workgroup counts, uniforms, bind groups.

use wgpu::util::DeviceExt;

/// The most workgroups along one dispatch dimension (WebGPU's guaranteed limit).
const MAX_GROUPS_PER_DIM: u32 = 65535;

/// Workgroup counts (x, y) covering `n` invocations in groups of `group`,
/// spread over y when x alone would exceed the limit. The shaders rebuild the
/// linear index as `gid.x + gid.y * groups.x * group`.
pub fn groups_1d(n: u32, group: u32) -> (u32, u32) {
    let g = n.div_ceil(group).max(1);
    if g <= MAX_GROUPS_PER_DIM {
        (g, 1)
    } else {
        let y = g.div_ceil(MAX_GROUPS_PER_DIM);
        (g.div_ceil(y), y)
    }
}

/// A uniform buffer holding `value`.
pub fn uniform<T: bytemuck::Pod>(device: &wgpu::Device, label: &str, value: &T) -> wgpu::Buffer {
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytemuck::bytes_of(value),
        usage: wgpu::BufferUsages::UNIFORM,
    })
}

/// A storage buffer of `bytes` (at least 16: a binding must not be empty).
pub fn storage(
    device: &wgpu::Device,
    label: &str,
    bytes: u64,
    extra: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE | extra,
        mapped_at_creation: false,
    })
}

/// A read-only storage buffer holding `items`; a binding must not be
/// empty, so an empty list gets one unused zeroed item.
pub fn upload<T: bytemuck::Pod>(device: &wgpu::Device, label: &str, items: &[T]) -> wgpu::Buffer {
    let one = [T::zeroed()];
    let data: &[T] = if items.is_empty() { &one } else { items };
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytemuck::cast_slice(data),
        usage: wgpu::BufferUsages::STORAGE,
    })
}

/// A bind group for group 0 of `pipeline` with `buffers` at bindings 0, 1, ...
/// (`None` skips a binding the entry point does not use).
pub fn bind(
    device: &wgpu::Device,
    pipeline: &wgpu::ComputePipeline,
    buffers: &[Option<&wgpu::Buffer>],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = buffers
        .iter()
        .enumerate()
        .filter_map(|(k, b)| {
            b.map(|b| wgpu::BindGroupEntry {
                binding: k as u32,
                resource: b.as_entire_binding(),
            })
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    })
}

/// A compute pipeline for `entry` of `module`, its layout derived from the shader.
pub fn pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: None,
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// A shader module from WGSL source.
pub fn module(device: &wgpu::Device, label: &str, source: &str) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dispatches_cover_every_invocation_within_the_limits() {
        for n in [
            1u32,
            64,
            65,
            65535 * 64,
            65535 * 64 + 1,
            3_000_000,
            40_000_000,
        ] {
            let (x, y) = groups_1d(n, 64);
            assert!(x <= MAX_GROUPS_PER_DIM && y <= MAX_GROUPS_PER_DIM);
            assert!(x as u64 * y as u64 * 64 >= n as u64);
        }
    }
}
