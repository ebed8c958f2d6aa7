//! Vulkan instance, device and queue, the memory allocator and the validation messenger.
//! Field order is drop order: the allocator goes before the device, the device before the instance.

use std::ffi::CStr;
use std::mem::ManuallyDrop;
use std::sync::{Arc, Mutex};

use anyhow::{anyhow, bail, Result};
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use super::device_setup::{create_device, create_instance, pick_device, DebugMessenger};
use crate::error::{vk_error, GpuError};

pub(super) const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";
/// llvmpipe's LP_MAX_TGSI_LOOP_ITERATIONS: each loop's budget per shader invocation.
pub(super) const LLVMPIPE_LOOP_LIMIT: u32 = 65535;
/// How long `submit_and_wait` waits for one submission by default. A submission's first dispatch
/// of a kernel includes llvmpipe's JIT compile, which takes up to a minute for a
/// scene-specialised ReSTIR kernel on an idle 2-core machine and several times that beside other
/// jobs (a 120 s limit was overrun there); GPUs with a hang watchdog report a lost device long
/// before this.
pub const DEFAULT_FENCE_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(600);

/// How [`Context::new`] picks and sets up the device.
#[derive(Debug, Clone, Default)]
pub struct ContextOptions {
    /// Device name substring or index in enumeration order; `None` picks the best device.
    pub device: Option<String>,
    /// Enables VK_LAYER_KHRONOS_validation and counts every message it reports. Debian 12's
    /// layer (1.3.239) is not safe for validated devices made or dropped on one thread while
    /// another thread uses one (a lock-free process-wide map; KhronosGroup/Vulkan-ValidationLayers
    /// issue 4391): keep validated contexts to one thread at a time.
    pub validation: bool,
    /// Bytes past which a scene array is reached by buffer device address rather than bound (at most
    /// maxStorageBufferRange, the default). Tests lower it so that small scenes take the addressed path.
    pub scene_binding_limit: Option<u64>,
    /// How long one submission may run before `submit_and_wait` gives up on it and the device
    /// is considered hung (`None`: [`DEFAULT_FENCE_TIMEOUT`]).
    pub fence_timeout: Option<std::time::Duration>,
}

/// What the chosen device is and the limits the renderers plan around.
#[derive(Debug, Clone)]
pub struct DeviceInfo {
    /// The driver's device name (e.g. "llvmpipe (LLVM 15.0.7, 256 bits)").
    pub name: String,
    /// CPU (lavapipe), integrated or discrete: CPU devices get uniform-buffer scene bindings.
    pub device_type: vk::PhysicalDeviceType,
    /// maxStorageBufferRange: the most bytes one storage-buffer binding may cover.
    pub max_storage_buffer_range: u64,
    /// maxUniformBufferRange: the most bytes one uniform-buffer binding may cover.
    pub max_uniform_buffer_range: u64,
    /// Bytes one scene array may take in a binding (maxStorageBufferRange, or less where
    /// `ContextOptions::scene_binding_limit` says so); larger ones are addressed.
    pub scene_binding_limit: u64,
    /// Whether bufferDeviceAddress is enabled: scene arrays past `scene_binding_limit` are then
    /// reached by address, bounded by `max_allocation_bytes` instead.
    pub buffer_device_address: bool,
    /// The largest single allocation (maxMemoryAllocationSize; lavapipe: 2 GiB).
    pub max_allocation_bytes: u64,
    /// Bytes of shared memory a compute workgroup may use (Vulkan's floor: 16384).
    pub max_compute_shared_memory: u32,
    /// Nanoseconds per timestamp tick (timestampPeriod).
    pub timestamp_period_ns: f32,
    /// Whether the compute queue writes timestamps (timestampValidBits > 0, timestampComputeAndGraphics).
    pub timestamps_supported: bool,
    /// Iterations each loop of one shader invocation may run in total before the driver silently
    /// leaves it (llvmpipe: 65535); `None` where no such cap is known.
    pub loop_iteration_limit: Option<u32>,
}

/// Collects the validation layer's output so that tests can fail on it. It may outlive the
/// context: leaks are reported while the device is destroyed.
#[derive(Default)]
pub struct ValidationLog {
    pub(super) errors: Mutex<Vec<String>>,
}

impl ValidationLog {
    /// The messages counted so far (errors and warnings), in order.
    pub fn messages(&self) -> Vec<String> {
        self.errors.lock().map(|e| e.clone()).unwrap_or_default()
    }
}

/// One Vulkan device with its compute queue, memory allocator and (optionally) validation messenger:
/// what every buffer, kernel and renderer is made on, shared as `Arc<Context>` (each holds a clone).
pub struct Context {
    allocator: ManuallyDrop<Mutex<Allocator>>,
    command_pool: vk::CommandPool,
    /// The compute queue all submissions use; raw handles, for code recording its own work.
    pub queue: vk::Queue,
    /// The compute queue's family index.
    pub queue_family: u32,
    /// The logical device (ash's loaded function table).
    pub device: ash::Device,
    /// The physical device chosen.
    pub physical_device: vk::PhysicalDevice,
    /// The device's name and limits.
    pub info: DeviceInfo,
    debug: DebugMessenger,
    validation_log: Arc<ValidationLog>,
    /// Compute pipelines created on this device (see `pipelines_created`).
    pipelines: std::sync::atomic::AtomicU64,
    fence_timeout: std::time::Duration,
    /// Set when a submission overran `fence_timeout`: the driver may still be executing it, so
    /// nothing made on this device may be destroyed or reused (see `is_hung`).
    hung: std::sync::atomic::AtomicBool,
    /// The raw instance handle.
    pub instance: ash::Instance,
    _entry: ash::Entry,
}

impl Context {
    /// Loads Vulkan, picks a device (`options.device`, else the first discrete, integrated,
    /// virtual then CPU device) and creates the queue, allocator and messenger.
    ///
    /// # Errors
    /// One line: no Vulkan loader, validation asked for without the layer installed, no device, no
    /// device matching `options.device` (the available ones listed), or a failed Vulkan call ([`GpuError`]).
    pub fn new(options: &ContextOptions) -> Result<Self> {
        let entry = unsafe { ash::Entry::load() }
            .map_err(|e| anyhow!("cannot load the Vulkan loader (libvulkan.so.1): {e}; run tools/setup.sh"))?;
        let validation = options.validation && {
            let layers = unsafe { entry.enumerate_instance_layer_properties() }.unwrap_or_default();
            let found = layers.iter().any(|l| l.layer_name_as_c_str().ok() == Some(VALIDATION_LAYER));
            if !found {
                bail!("validation requested but VK_LAYER_KHRONOS_validation is not installed (package vulkan-validationlayers)");
            }
            true
        };
        let validation_log = Arc::<ValidationLog>::default();
        // From here on a failure must destroy the instance; the guard does that until ownership moves.
        let guard = create_instance(&entry, validation, &validation_log)?;
        let (physical_device, queue_family, mut info) = pick_device(guard.instance(), options.device.as_deref())?;
        info.scene_binding_limit = options
            .scene_binding_limit
            .map_or(info.max_storage_buffer_range, |l| l.min(info.max_storage_buffer_range));
        let (device, queue, command_pool) = create_device(guard.instance(), physical_device, queue_family, info.buffer_device_address)?;
        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: guard.instance().clone(),
            device: device.clone(),
            physical_device,
            debug_settings: Default::default(),
            buffer_device_address: info.buffer_device_address,
            allocation_sizes: Default::default(),
        });
        let allocator = match allocator {
            Ok(a) => a,
            Err(e) => {
                unsafe {
                    device.destroy_command_pool(command_pool, None);
                    device.destroy_device(None);
                }
                bail!("cannot create the GPU memory allocator: {e}");
            }
        };
        let (instance, debug) = guard.release();
        Ok(Self {
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            command_pool,
            queue,
            queue_family,
            device,
            physical_device,
            info,
            debug,
            validation_log,
            pipelines: std::sync::atomic::AtomicU64::new(0),
            fence_timeout: options.fence_timeout.unwrap_or(DEFAULT_FENCE_TIMEOUT),
            hung: std::sync::atomic::AtomicBool::new(false),
            instance,
            _entry: entry,
        })
    }

    /// The device's memory allocator, locked (a poisoned lock is recovered: the allocator
    /// holds no invariant a panic elsewhere could break).
    pub fn allocator(&self) -> std::sync::MutexGuard<'_, Allocator> {
        self.allocator.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// Every validation message (errors and warnings) reported so far.
    pub fn validation_messages(&self) -> Vec<String> {
        self.validation_log.messages()
    }

    /// Whether the validation layer is on for this device (`ContextOptions::validation`).
    pub fn validated(&self) -> bool {
        self.debug.is_some()
    }

    /// The log itself, to read after the context is dropped (leaked objects are reported then).
    pub fn validation_log(&self) -> Arc<ValidationLog> {
        self.validation_log.clone()
    }

    /// Fails if the validation layer has reported anything; tests call this at their end.
    pub fn check_validation(&self) -> Result<(), GpuError> {
        let messages = self.validation_messages();
        match messages.first() {
            None => Ok(()),
            Some(first) => Err(GpuError::Validation {
                count: messages.len() as u32,
                first: first.clone(),
            }),
        }
    }

    /// The compute pipelines created on this device so far: a renderer creates all of its
    /// own at start-up, so a run's count stays put across its frames.
    pub fn pipelines_created(&self) -> u64 {
        self.pipelines.load(std::sync::atomic::Ordering::Relaxed)
    }

    pub(super) fn count_pipeline(&self) {
        self.pipelines.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    }

    /// Checks a storage binding against maxStorageBufferRange before anything is allocated.
    pub fn check_binding_size(&self, what: &str, bytes: u64) -> Result<(), GpuError> {
        if bytes > self.info.max_storage_buffer_range {
            return Err(GpuError::BindingTooLarge {
                what: what.to_string(),
                needed: bytes,
                limit: self.info.max_storage_buffer_range,
            });
        }
        Ok(())
    }

    /// Whether a submission overran the fence timeout. The driver may still be executing it,
    /// reading its command buffer, descriptor sets, pipelines and buffers; so from then on every
    /// object made on this device (buffers, kernels, timers, the device itself) is leaked
    /// rather than destroyed when dropped, and no further work is submitted. Destroying them
    /// under a running submission crashed lavapipe (docs/testing.md, "Crashes").
    pub fn is_hung(&self) -> bool {
        self.hung.load(std::sync::atomic::Ordering::Acquire)
    }

    fn hung_error(&self) -> GpuError {
        GpuError::Timeout {
            seconds: self.fence_timeout.as_secs(),
        }
    }

    /// Records commands with `record`, submits them with a fence and waits for completion.
    ///
    /// # Errors
    /// [`GpuError::Timeout`] when the submission does not finish within the fence timeout, or
    /// when an earlier one did not (the device is then hung: see [`Context::is_hung`]); the
    /// command buffer and fence of an unfinished submission are leaked, never freed under it.
    /// [`GpuError::DeviceLost`] and other Vulkan errors as reported.
    pub fn submit_and_wait(&self, record: impl FnOnce(vk::CommandBuffer)) -> Result<(), GpuError> {
        if self.is_hung() {
            return Err(self.hung_error());
        }
        let alloc_info = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.command_pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        let cmd = unsafe { self.device.allocate_command_buffers(&alloc_info) }.map_err(vk_error("allocating a command buffer"))?[0];
        let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        let recorded = unsafe { self.device.begin_command_buffer(cmd, &begin) }
            .map_err(vk_error("beginning a command buffer"))
            .and_then(|_| {
                record(cmd);
                unsafe { self.device.end_command_buffer(cmd) }.map_err(vk_error("ending a command buffer"))
            })
            .and_then(|_| unsafe { self.device.create_fence(&vk::FenceCreateInfo::default(), None) }.map_err(vk_error("creating a fence")));
        let fence = match recorded {
            Ok(fence) => fence,
            Err(e) => {
                unsafe { self.device.free_command_buffers(self.command_pool, &[cmd]) };
                return Err(e);
            }
        };
        let cmds = [cmd];
        let submit = [vk::SubmitInfo::default().command_buffers(&cmds)];
        let timeout_ns = u64::try_from(self.fence_timeout.as_nanos()).unwrap_or(u64::MAX);
        let waited = match unsafe { self.device.queue_submit(self.queue, &submit, fence) } {
            Err(e) => Err(vk_error("submitting GPU work")(e)),
            Ok(()) => unsafe { self.device.wait_for_fences(&[fence], true, timeout_ns) }.map_err(|e| match e {
                vk::Result::TIMEOUT => {
                    // The driver still owns the command buffer and everything it references:
                    // the fence and the command buffer are leaked, and the device is marked
                    // so that no owner of its objects destroys them.
                    self.hung.store(true, std::sync::atomic::Ordering::Release);
                    self.hung_error()
                }
                other => vk_error("waiting for GPU work")(other),
            }),
        };
        if !self.is_hung() {
            unsafe {
                self.device.destroy_fence(fence, None);
                self.device.free_command_buffers(self.command_pool, &[cmd]);
            }
        }
        waited
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        if self.is_hung() {
            // A submission may still run and may never end: waiting could hang, destroying
            // would free what it reads. The device, its memory and the instance are leaked, and
            // so is the validation log that the instance's messenger still points at.
            std::mem::forget(self.validation_log.clone());
            return;
        }
        unsafe {
            // A lost device may refuse to idle; teardown proceeds regardless.
            let _ = self.device.device_wait_idle();
            ManuallyDrop::drop(&mut self.allocator);
            self.device.destroy_command_pool(self.command_pool, None);
            self.device.destroy_device(None);
            if let Some((loader, messenger)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}
