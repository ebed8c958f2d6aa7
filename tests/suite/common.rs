//! Shared test helpers: a validated GPU context, oracle-kernel runs and tolerant comparisons.

use std::path::PathBuf;
use std::sync::Arc;

use restir_pt::oracle_types::{BsdfOracleInput, BsdfOracleOutput};
use restir_pt::render::SceneGpu;
use restir_pt::vk::{BindingSlot, BoundBuffer, Buffer, Context, ContextOptions, Kernel};

/// NaN bits pre-filled into every output buffer, so that an unwritten slot fails a comparison.
pub const NAN_FILL: u32 = 0x7fc0_0000;

pub fn gpu() -> Arc<Context> {
    gpu_with_scene_binding_limit(None)
}

/// A validated context whose scene arrays past `limit` bytes are reached by device address
/// (`ContextOptions::scene_binding_limit`): small scenes then take the large-scene path.
pub fn gpu_with_scene_binding_limit(limit: Option<u64>) -> Arc<Context> {
    let ctx = Context::new(&ContextOptions {
        device: None,
        validation: true,
        scene_binding_limit: limit,
        ..Default::default()
    })
    .expect("a Vulkan device with validation layers (tools/setup.sh)");
    Arc::new(ctx)
}

/// Fails the test if the validation layer reported anything during it.
pub fn assert_clean(ctx: &Context) {
    if let Err(e) = ctx.check_validation() {
        panic!("{e}");
    }
}

pub fn repo_path(relative: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(relative)
}

/// The files with extension `ext` under `dir` (a path from the repository's root, "" for all of
/// it), as paths from the root with '/' separators, sorted; build output, git's and Python's
/// environment folders are skipped.
pub fn repository_files(dir: &str, ext: &str) -> Vec<String> {
    fn walk(relative: &str, ext: &str, out: &mut Vec<String>) {
        for entry in std::fs::read_dir(repo_path(relative)).expect("readable folder").flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            let path = if relative.is_empty() {
                name.clone()
            } else {
                format!("{relative}/{name}")
            };
            if entry.path().is_dir() {
                if !matches!(name.as_str(), "target" | ".git" | ".venv" | "node_modules") {
                    walk(&path, ext, out);
                }
            } else if entry.path().extension().is_some_and(|e| e == ext) {
                out.push(path);
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, ext, &mut out);
    out.sort();
    out
}

/// Runs an oracle kernel over `count` items. The `leading` buffers keep their bindings; the
/// storage blocks named in `inputs` follow them in order, then the block `Outputs` of
/// `output_words` 32-bit words pre-filled with NaN, which is returned. Kernel::new checks each
/// name against the block the kernel declares at that binding.
pub fn run_oracle<T: bytemuck::Pod>(
    ctx: &Arc<Context>,
    kernel: &str,
    leading: &[BoundBuffer],
    inputs: &[(&'static str, &[u8])],
    output_words: usize,
    count: u32,
) -> Vec<T> {
    run_oracle_with_defines(ctx, kernel, &[], leading, inputs, output_words, count)
}

/// `run_oracle` with the kernel compiled with `defines`.
pub fn run_oracle_with_defines<T: bytemuck::Pod>(
    ctx: &Arc<Context>,
    kernel: &str,
    defines: &[(&str, &str)],
    leading: &[BoundBuffer],
    inputs: &[(&'static str, &[u8])],
    output_words: usize,
    count: u32,
) -> Vec<T> {
    let build = |layout: &[BindingSlot]| Kernel::new(ctx, kernel, defines, layout, 4).unwrap();
    run_built_oracle(ctx, build, leading, inputs, output_words, count)
}

/// `run_oracle` for a kernel that includes the scene bindings, compiled as the renderers compile
/// theirs (`SceneGpu::defines`, then `defines`): set 0 holds the scene at 0-4 (`frame` its
/// parameters), then the inputs and outputs; set 1 the surface attributes and textures of a
/// scene that has them (`SceneGpu::kernel`).
#[allow(clippy::too_many_arguments)]
pub fn run_scene_oracle<T: bytemuck::Pod>(
    ctx: &Arc<Context>,
    scene_gpu: &SceneGpu,
    frame: &Buffer,
    kernel: &str,
    defines: &[(&str, &str)],
    inputs: &[(&'static str, &[u8])],
    output_words: usize,
    count: u32,
) -> Vec<T> {
    let mut all = scene_gpu.defines();
    all.extend_from_slice(defines);
    let build = |layout: &[BindingSlot]| scene_gpu.kernel(kernel, &all, layout.to_vec(), 4).unwrap();
    run_built_oracle(ctx, build, &scene_gpu.buffers(frame), inputs, output_words, count)
}

/// The input of oracle/bsdf_oracle.comp for normals `ng` (geometric) and `ns` (shading),
/// directions `wo` and `wi` and `bsdf_sample`'s uniforms `u`.
pub fn bsdf_input(ng: glam::Vec3, ns: glam::Vec3, wo: glam::Vec3, wi: glam::Vec3, u: glam::Vec4) -> BsdfOracleInput {
    BsdfOracleInput {
        geometric_normal: ng.to_array(),
        shading_normal: ns.to_array(),
        wo: wo.to_array(),
        wi: wi.to_array(),
        u: u.to_array(),
        ..Default::default()
    }
}

/// Runs oracle/bsdf_oracle.comp (`bsdf_eval_pdf` and `bsdf_sample`) on one input per material.
pub fn run_bsdf_oracle(
    ctx: &Arc<Context>,
    materials: &[restir_pt::gpu_types::Material],
    inputs: &[BsdfOracleInput],
) -> Vec<BsdfOracleOutput> {
    assert_eq!(inputs.len(), materials.len(), "one input per material");
    run_oracle(
        ctx,
        "oracle/bsdf_oracle.comp",
        &[],
        &[
            ("Materials", bytemuck::cast_slice(materials)),
            ("Inputs", bytemuck::cast_slice(inputs)),
        ],
        materials.len() * std::mem::size_of::<BsdfOracleOutput>() / 4,
        materials.len() as u32,
    )
}

/// Runs an oracle kernel that binds everything in set 0: the scene at 0-4 (default frame
/// parameters), its surface attributes and textures at 5-8 (SURFACE_SET 0, SURFACE_BINDING 5 in
/// the kernel), `Inputs` at 9 (one `I` per item) and `Outputs` at 10 (one `O` per item, which
/// come back); the push constant is the item count.
pub fn run_surface_set0_oracle<I: bytemuck::Pod, O: bytemuck::Pod>(
    ctx: &Arc<Context>,
    scene_gpu: &SceneGpu,
    kernel: &str,
    inputs: &[I],
) -> Vec<O> {
    run_surface_set0_oracle_with(ctx, scene_gpu, kernel, &[], inputs)
}

/// [`run_surface_set0_oracle`] with `extra` defines after the scene's (e.g. SCENE_BRUTE_FORCE,
/// which the path tracer adds for small scenes).
pub fn run_surface_set0_oracle_with<I: bytemuck::Pod, O: bytemuck::Pod>(
    ctx: &Arc<Context>,
    scene_gpu: &SceneGpu,
    kernel: &str,
    extra: &[(&'static str, &'static str)],
    inputs: &[I],
) -> Vec<O> {
    let items = inputs.len();
    use restir_pt::gpu_types::FrameParams;
    use restir_pt::shader_interface::SurfaceBinding;
    use restir_pt::vk::{Binding, BindingFamilyExt, BufferUsage};
    let surface = scene_gpu.surface.as_ref().expect("the scene has attributes");
    let params = Buffer::new(ctx, "params", std::mem::size_of::<FrameParams>() as u64, BufferUsage::Params).unwrap();
    params.write(&[FrameParams::default()]).unwrap();
    let input = Buffer::from_slice(ctx, "inputs", inputs).unwrap();
    let output = Buffer::new(ctx, "outputs", (items * std::mem::size_of::<O>()) as u64, BufferUsage::Storage).unwrap();
    output.fill(NAN_FILL).unwrap();
    let mut buffers = scene_gpu.buffers(&params);
    buffers.extend(
        SurfaceBinding::ALL
            .iter()
            .zip(&surface.buffers)
            .map(|(&b, buffer)| b.slot_at(0, 5, Binding::Storage).to(buffer)),
    );
    buffers.extend([
        BindingSlot::storage(9, "Inputs").to(&input),
        BindingSlot::storage(10, "Outputs").to(&output),
    ]);
    let layout: Vec<BindingSlot> = buffers.iter().map(|b| b.slot).collect();
    let mut defines = scene_gpu.defines();
    defines.extend_from_slice(extra);
    let k = Kernel::new(ctx, kernel, &defines, &layout, 4).unwrap();
    k.bind(&buffers).unwrap();
    k.run_1d(items as u32, 64, bytemuck::bytes_of(&(items as u32))).unwrap();
    output.read::<O>(items).unwrap()
}

/// Runs the oracle kernel `build` makes from the layout of `leading`, `inputs` and `Outputs`.
fn run_built_oracle<T: bytemuck::Pod>(
    ctx: &Arc<Context>,
    build: impl FnOnce(&[BindingSlot]) -> Kernel,
    leading: &[BoundBuffer],
    inputs: &[(&'static str, &[u8])],
    output_words: usize,
    count: u32,
) -> Vec<T> {
    let input_buffers: Vec<Buffer> = inputs
        .iter()
        .map(|(name, data)| Buffer::from_slice(ctx, name, data).unwrap())
        .collect();
    let output = Buffer::new(ctx, "oracle output", output_words as u64 * 4, restir_pt::vk::BufferUsage::Storage).unwrap();
    output.fill(NAN_FILL).unwrap();
    let first = leading.len() as u32;
    let mut bindings: Vec<BoundBuffer> = leading.to_vec();
    for (i, ((name, _), buffer)) in inputs.iter().zip(&input_buffers).enumerate() {
        bindings.push(BindingSlot::storage(first + i as u32, name).to(buffer));
    }
    bindings.push(BindingSlot::storage(first + inputs.len() as u32, "Outputs").to(&output));
    let layout: Vec<BindingSlot> = bindings.iter().map(|b| b.slot).collect();
    let k = build(&layout);
    k.bind(&bindings).unwrap();
    k.run_1d(count, 64, bytemuck::bytes_of(&count)).unwrap();
    let words = output.read::<u32>(output_words).unwrap();
    bytemuck::cast_slice(&words).to_vec()
}

/// |a - b| <= tol * max(1, |a|, |b|): absolute near zero, relative for large values.
pub fn close(a: f32, b: f32, tol: f32) -> bool {
    if a.is_nan() || b.is_nan() {
        return false;
    }
    (a - b).abs() <= tol * 1f32.max(a.abs()).max(b.abs())
}

/// Component-wise `close` of a GLSL result and its Rust twin; `what` names the case on failure.
pub fn assert_vec3_close(what: impl std::fmt::Display, gpu: glam::Vec3, cpu: glam::Vec3, tol: f32) {
    for k in 0..3 {
        assert!(close(gpu[k], cpu[k], tol), "{what}: GLSL {gpu} vs Rust {cpu}");
    }
}

/// A small deterministic generator for test inputs (SplitMix64).
pub struct TestRng(pub u64);

impl TestRng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    pub fn uniform(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    pub fn unit_vector(&mut self) -> glam::Vec3 {
        restir_pt::shading::sampling::sample_uniform_sphere(glam::Vec2::new(self.uniform(), self.uniform()))
    }
}

/// Writes `contents` to a fresh file under the system temp folder and returns its path.
pub fn temp_file(name: &str, contents: &[u8]) -> PathBuf {
    static COUNTER: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("restir-pt-test-{}-{n}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, contents).unwrap();
    path
}

/// The kernels' MIS_MODE for a resampling MIS of the Rust estimator (`Uniform`, a negative
/// control of the Rust tests only, has no kernel and maps to the generalized balance heuristic).
pub fn mis_mode(mis: restir_pt::shading::gris::Mis) -> &'static str {
    use restir_pt::render::ReuseMis;
    match mis {
        restir_pt::shading::gris::Mis::Pairwise => ReuseMis::Pairwise,
        _ => ReuseMis::GeneralizedBalance,
    }
    .glsl_name()
}
