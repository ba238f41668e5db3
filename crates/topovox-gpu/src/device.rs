//! The device layer of both wgpu crates (this one and `topovox-view`, which
//! depends on it): one way to find an adapter, open a device whose errors
//! become values instead of panics, build a shader from its parts, read
//! buffers back and turn timestamps into time — with one error type,
//! [`GpuError`]. Written by hand because it is the glue between wgpu's
//! callbacks and this project's errors; wgpu itself does the work.

use std::sync::{Arc, Mutex};

use crate::GpuError;

/// What a caller needs of the device.
#[derive(Clone, Copy, Debug)]
pub struct DeviceOptions<'a> {
    /// The device's label (shown in driver messages).
    pub label: &'static str,
    /// An adapter that can present to this surface (the viewer's window).
    pub surface: Option<&'a wgpu::Surface<'a>>,
    /// Features the caller cannot work without, each with what it is for
    /// (refused with [`GpuError::MissingFeature`] naming it).
    pub required: &'a [(wgpu::Features, &'static str)],
    /// Features taken when the adapter offers them.
    pub optional: wgpu::Features,
}

/// An open device and queue whose uncaptured errors and loss are kept
/// for the next [`Device::check`].
pub struct Device {
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// The adapter it was opened on (a window's surface is configured for it).
    pub adapter: wgpu::Adapter,
    /// The adapter's description.
    pub info: wgpu::AdapterInfo,
    /// The features the device was opened with.
    pub features: wgpu::Features,
    /// The adapter's limits (the device asks for the buffer, texture and
    /// array sizes among them).
    pub limits: wgpu::Limits,
    /// The first error reported outside a call's own checks (validation,
    /// out of memory, device lost).
    errors: Arc<Mutex<Option<String>>>,
}

/// The default adapter of `instance` (high performance preferred, able to
/// present to `surface` when given) that has every `required` feature.
pub fn adapter(
    instance: &wgpu::Instance,
    surface: Option<&wgpu::Surface<'_>>,
    required: &[(wgpu::Features, &'static str)],
) -> Result<wgpu::Adapter, GpuError> {
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        compatible_surface: surface,
        ..Default::default()
    }))
    .map_err(|_| GpuError::NoAdapter)?;
    if let Some((_, what)) = required.iter().find(|(f, _)| !adapter.features().contains(*f)) {
        return Err(GpuError::MissingFeature { adapter: adapter.get_info().name, what });
    }
    Ok(adapter)
}

impl Device {
    /// Opens a device on the adapter [`adapter`] finds.
    pub fn open(instance: &wgpu::Instance, o: &DeviceOptions<'_>) -> Result<Device, GpuError> {
        let adapter = adapter(instance, o.surface, o.required)?;
        let required = o.required.iter().fold(wgpu::Features::empty(), |all, (f, _)| all | *f);
        let features = required | (adapter.features() & o.optional);
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some(o.label),
            required_features: features,
            required_limits: wgpu::Limits {
                max_storage_buffer_binding_size: limits.max_storage_buffer_binding_size,
                max_buffer_size: limits.max_buffer_size,
                max_texture_dimension_2d: limits.max_texture_dimension_2d,
                max_texture_array_layers: limits.max_texture_array_layers,
                ..wgpu::Limits::downlevel_defaults()
            },
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .map_err(|e| GpuError::Device(e.to_string()))?;
        let errors: Arc<Mutex<Option<String>>> = Arc::default();
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            if let Ok(mut slot) = sink.lock() {
                slot.get_or_insert_with(|| e.to_string().lines().next().unwrap_or("unknown error").to_string());
            }
        }));
        let sink = errors.clone();
        device.set_device_lost_callback(move |reason, msg| {
            if let Ok(mut slot) = sink.lock() {
                slot.get_or_insert_with(|| format!("device lost ({reason:?}): {msg}"));
            }
        });
        Ok(Device { device, queue, info: adapter.get_info(), adapter, features, limits, errors })
    }

    /// The first error the device reported since the last check, if any.
    pub fn check(&self) -> Result<(), GpuError> {
        match self.errors.lock().ok().and_then(|mut e| e.take()) {
            Some(msg) => Err(GpuError::Device(msg)),
            None => Ok(()),
        }
    }

    /// The device writes timestamps around passes (opened with
    /// `TIMESTAMP_QUERY`).
    pub fn timestamps(&self) -> bool {
        self.features.contains(wgpu::Features::TIMESTAMP_QUERY)
    }

    /// The largest 2D texture side (pictures, the rasterizer's viewport).
    pub fn max_texture_side(&self) -> u32 {
        self.limits.max_texture_dimension_2d
    }

    /// The adapter's name and backend, e.g. "llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan)".
    pub fn adapter_name(&self) -> String {
        format!("{} ({:?})", self.info.name, self.info.backend)
    }

    /// A shader module from WGSL parts, joined in order (a crate's common
    /// definitions first).
    pub fn shader(&self, label: &str, parts: &[&str]) -> wgpu::ShaderModule {
        self.device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(parts.join("\n").into()),
        })
    }

    /// Maps every buffer for reading and waits until all are (after the
    /// submitted work that fills them).
    pub fn map_all(&self, bufs: &[wgpu::BufferSlice<'_>]) -> Result<(), GpuError> {
        let rx: Vec<_> = bufs
            .iter()
            .map(|b| {
                let (tx, rx) = std::sync::mpsc::channel();
                b.map_async(wgpu::MapMode::Read, move |r| {
                    let _ = tx.send(r);
                });
                rx
            })
            .collect();
        self.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| GpuError::Device(e.to_string()))?;
        self.check()?;
        for rx in rx {
            rx.recv().map_err(|e| GpuError::Readback(e.to_string()))?.map_err(|e| GpuError::Readback(e.to_string()))?;
        }
        Ok(())
    }

    /// Submits `enc` after copying each buffer's first bytes to a readback
    /// buffer, waits, and returns the bytes.
    pub fn read_buffers(&self, mut enc: wgpu::CommandEncoder, bufs: &[(&wgpu::Buffer, u64)]) -> Result<Vec<Vec<u8>>, GpuError> {
        let reads: Vec<wgpu::Buffer> = bufs
            .iter()
            .map(|(b, size)| {
                let r = self.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("readback"),
                    size: *size,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                enc.copy_buffer_to_buffer(b, 0, &r, 0, *size);
                r
            })
            .collect();
        self.queue.submit([enc.finish()]);
        self.map_all(&reads.iter().map(|b| b.slice(..)).collect::<Vec<_>>())?;
        reads.iter().map(|b| Ok(mapped(b.slice(..))?.to_vec())).collect()
    }

    /// Seconds between timestamp pairs `(begin, end)` summed, or `None`
    /// when the driver wrote none (lavapipe offers the feature but writes
    /// zeros: no time, not zero time).
    pub fn timestamp_seconds(&self, stamps: &[u64]) -> Option<f64> {
        let ticks: u64 = stamps.chunks_exact(2).map(|p| p[1].saturating_sub(p[0])).sum();
        (ticks > 0).then(|| ticks as f64 * self.queue.get_timestamp_period() as f64 * 1e-9)
    }
}

/// The bytes of a mapped buffer slice.
pub fn mapped<'a>(slice: wgpu::BufferSlice<'a>) -> Result<wgpu::BufferView, GpuError> {
    slice.get_mapped_range().map_err(|e| GpuError::Readback(e.to_string()))
}

/// The instance for headless work: Vulkan, Metal and DX12 (`WGPU_BACKEND`
/// chooses others). Not OpenGL: its EGL setup probes for a Wayland display
/// and, on a headless machine without `XDG_RUNTIME_DIR`, prints "error:"
/// lines on stderr of runs that succeed; no compute path uses it.
pub fn headless() -> wgpu::InstanceDescriptor {
    quiet_without_display();
    wgpu::InstanceDescriptor { backends: wgpu::Backends::PRIMARY, ..wgpu::InstanceDescriptor::new_without_display_handle() }.with_env()
}

/// On a machine without a display (no `WAYLAND_DISPLAY`, `DISPLAY` or
/// valid `XDG_RUNTIME_DIR`), turns off Mesa's Vulkan device-selection
/// layer (`NODEVICE_SELECT=1`) unless the user chose a device with it
/// (`MESA_VK_DEVICE_SELECT`): while devices are enumerated it looks for a
/// Wayland display and prints "error: XDG_RUNTIME_DIR is invalid" on
/// stderr of runs that succeed. It only orders devices by the display's,
/// which a machine without one does not have. Once per process; the CLI
/// calls it first thing, while it has one thread.
pub fn quiet_without_display() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let set = |v: &str| std::env::var_os(v).is_some_and(|x| !x.is_empty());
        let runtime_dir = std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_dir());
        let display = set("WAYLAND_DISPLAY") || set("DISPLAY") || runtime_dir;
        if !display && !set("MESA_VK_DEVICE_SELECT") && !set("NODEVICE_SELECT") {
            std::env::set_var("NODEVICE_SELECT", "1");
        }
    });
}

/// What the exact path cannot do without.
pub(crate) const REQUIRED: &[(wgpu::Features, &str)] = &[(wgpu::Features::SHADER_INT64, "64-bit integers in shaders (SHADER_INT64)")];

/// The default adapter (high performance preferred), if it has what the
/// exact path needs.
fn voxelization_adapter() -> Result<wgpu::Adapter, GpuError> {
    adapter(&wgpu::Instance::new(headless()), None, REQUIRED)
}

/// Is the adapter [`Gpu::new`](crate::Gpu::new) would open a hardware one (not lavapipe or
/// WARP)? Asks for the adapter only: no device, no pipelines, so a caller
/// deciding whether to use the GPU pays little.
pub fn hardware_adapter() -> Result<bool, GpuError> {
    if !hardware_plausible() {
        return Ok(false);
    }
    Ok(voxelization_adapter()?.get_info().device_type != wgpu::DeviceType::Cpu)
}

/// On Linux a hardware GPU is reached through a DRM render node or the
/// NVIDIA device files; without either there is none to find, and asking
/// the Vulkan loader would only wake Mesa's software driver and its
/// device-selection layer, which prints to stderr when no display is set
/// up (`XDG_RUNTIME_DIR is invalid`). Elsewhere (Metal, DX12), ask.
fn hardware_plausible() -> bool {
    if !cfg!(target_os = "linux") {
        return true;
    }
    let any_in = |dir: &str, prefix: &str| {
        std::fs::read_dir(dir).is_ok_and(|d| d.flatten().any(|e| e.file_name().to_string_lossy().starts_with(prefix)))
    };
    any_in("/dev/dri", "renderD") || any_in("/dev", "nvidia")
}
