//! The option groups several commands share, declared once for clap and flattened into each
//! command's own declaration (`#[command(flatten)]`). Defaults come from the library's settings
//! (`RenderSettings`, `RestirSettings`), so that the CLI and the library cannot drift apart.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, ValueEnum};
use glam::Vec3;

use super::scene_path;
use super::sweep::SweepMode;
use restir_pt::image_io::Exposure;
use restir_pt::render::{History, RenderSettings, RestirSettings, ReuseMis, ShiftKind};
use restir_pt::scene::{ArrayLimit, LoadOptions};

/// An on/off switch written `--flag on|off`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Toggle {
    On,
    Off,
}

impl Toggle {
    pub fn on(self) -> bool {
        self == Toggle::On
    }

    fn from_bool(on: bool) -> Self {
        if on {
            Toggle::On
        } else {
            Toggle::Off
        }
    }
}

/// The Vulkan device and the validation layer.
#[derive(Args, Debug, Clone, Default)]
pub struct DeviceArgs {
    /// Vulkan device to use: a name substring or an index (the chosen device is printed).
    #[arg(long, value_name = "NAME|INDEX")]
    pub device: Option<String>,
    /// Enable the Vulkan validation layer (always on in debug builds); any message fails the run.
    #[arg(long)]
    pub validate: bool,
}

impl DeviceArgs {
    /// Whether the validation layer is on: asked for, or a debug build.
    pub fn validation(&self) -> bool {
        self.validate || cfg!(debug_assertions)
    }
}

/// ReSTIR PT's settings (`RestirSettings`), all defaulting to `RestirSettings::default()`.
#[derive(Args, Debug, Clone)]
pub struct RestirArgs {
    /// ReSTIR PT: the shift mapping used for reuse.
    #[arg(long, value_enum, default_value_t = RestirSettings::default().shift)]
    pub shift: ShiftKind,
    /// ReSTIR PT: resampling MIS weights.
    #[arg(long, value_enum, default_value_t = RestirSettings::default().mis)]
    pub mis: ReuseMis,
    /// ReSTIR PT: reuse the previous frame's reservoirs.
    #[arg(long, value_enum, default_value_t = Toggle::from_bool(RestirSettings::default().temporal))]
    pub temporal: Toggle,
    /// ReSTIR PT: the reservoirs the next frame's temporal reuse reads, those before spatial
    /// reuse (temporal) or after it (spatial).
    #[arg(long, value_enum, default_value_t = RestirSettings::default().history)]
    pub history: History,
    /// ReSTIR PT: spatial neighbours per round (0 turns spatial reuse off; at most 8).
    #[arg(long, default_value_t = RestirSettings::default().spatial)]
    pub spatial: u32,
    /// ReSTIR PT: spatial reuse radius in pixels.
    #[arg(long, default_value_t = RestirSettings::default().radius, allow_negative_numbers = true)]
    pub radius: f32,
    /// ReSTIR PT: spatial reuse rounds (1 to 3).
    #[arg(long, default_value_t = RestirSettings::default().rounds)]
    pub rounds: u32,
    /// ReSTIR PT: the temporal input's confidence is capped at this multiple of the current M,
    /// and an unmoved camera's running mean of the directly seen emission at this many frames
    /// (default 20; 2 where `render` averages a still camera's frames to a time budget).
    #[arg(long, allow_negative_numbers = true)]
    pub m_cap: Option<f32>,
    /// ReSTIR PT: initial paths traced per reservoir and frame.
    #[arg(long, default_value_t = RestirSettings::default().candidates)]
    pub candidates: u32,
    /// ReSTIR PT: independent reservoirs per pixel (1 to 16), each with its own paths, history
    /// and neighbours; the pixel shows their mean, which averages down the colour noise of
    /// one luminance-resampled path.
    #[arg(long, default_value_t = RestirSettings::default().reservoirs)]
    pub reservoirs: u32,
    /// ReSTIR PT: camera rays per pixel and frame that estimate the emission seen directly
    /// (1: only the reservoir's primary ray); each further ray costs one closest-hit trace.
    #[arg(long, default_value_t = RestirSettings::default().emission_rays)]
    pub emission_rays: u32,
}

impl RestirArgs {
    /// The settings these flags give; the rest are `RestirSettings::default()`'s.
    pub fn settings(&self) -> RestirSettings {
        RestirSettings {
            shift: self.shift,
            mis: self.mis,
            temporal: self.temporal.on(),
            history: self.history,
            spatial: self.spatial,
            radius: self.radius,
            rounds: self.rounds,
            m_cap: self.m_cap.unwrap_or(RestirSettings::default().m_cap),
            candidates: self.candidates,
            reservoirs: self.reservoirs,
            emission_rays: self.emission_rays,
            ..Default::default()
        }
    }

    /// The ReSTIR PT flags set to something other than their default, as `--flag value`: the
    /// path tracer ignores them, and a user who set one should hear so.
    pub fn changed_flags(&self) -> Vec<String> {
        let set = self.settings();
        let default = RestirSettings::default();
        let mut changed = vec![];
        let mut note = |differs: bool, flag: &str, value: String| {
            if differs {
                changed.push(format!("--{flag} {value}"));
            }
        };
        note(set.shift != default.shift, "shift", set.shift.name().into());
        note(set.mis != default.mis, "mis", set.mis.name().into());
        note(
            set.temporal != default.temporal,
            "temporal",
            if set.temporal { "on" } else { "off" }.into(),
        );
        note(
            set.history != default.history,
            "history",
            format!("{:?}", set.history).to_lowercase(),
        );
        note(set.spatial != default.spatial, "spatial", set.spatial.to_string());
        note(set.radius != default.radius, "radius", set.radius.to_string());
        note(set.rounds != default.rounds, "rounds", set.rounds.to_string());
        note(set.m_cap != default.m_cap, "m-cap", set.m_cap.to_string());
        note(set.candidates != default.candidates, "candidates", set.candidates.to_string());
        note(set.reservoirs != default.reservoirs, "reservoirs", set.reservoirs.to_string());
        note(
            set.emission_rays != default.emission_rays,
            "emission-rays",
            set.emission_rays.to_string(),
        );
        changed
    }
}

/// The scene: a glTF file (default: the bundled Cornell box), which of its scenes, and an
/// environment replacing its own.
#[derive(Args, Debug, Clone, Default)]
pub struct SceneArgs {
    /// glTF 2.0 scene (.gltf or .glb); defaults to the Cornell box built into the binary
    /// (scenes/cornell.gltf).
    pub scene: Option<PathBuf>,
    /// The glTF scene to use (index into the file's scenes; default: its default scene).
    #[arg(long = "scene")]
    pub scene_index: Option<usize>,
    /// Environment replacing the scene's (and the default one): a radiance R,G,B, an
    /// equirectangular FILE.exr or FILE.hdr importance-sampled by luminance (Mitsuba 3's
    /// orientation: the centre column faces +Z), or `none` (the file's lights alone, no default
    /// environment).
    #[arg(long, value_parser = parse_env, value_name = "R,G,B|FILE|none", allow_hyphen_values = true)]
    pub env: Option<EnvArg>,
    /// Turns the environment map about the up axis (+Y) by DEGREES (right-handed: 90 brings the
    /// map's centre column from +Z to +X).
    #[arg(long, value_parser = parse_degrees, value_name = "DEGREES", allow_hyphen_values = true, default_value_t = 0.0)]
    pub env_rotation: f32,
}

/// `--env-rotation`: a finite angle in degrees.
pub fn parse_degrees(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(d) if d.is_finite() => Ok(d),
        _ => Err(format!("{s:?} is not a finite angle in degrees")),
    }
}

impl SceneArgs {
    /// The file to load: the one given, or the built-in Cornell box (errors: it cannot be
    /// written to a cache or temporary folder).
    pub fn path(&self) -> anyhow::Result<PathBuf> {
        scene_path(self.scene.as_deref())
    }

    /// What to load besides the file; `array_limit` is the device's limit on one scene array
    /// (`render::scene_array_limit`), None before a device is open.
    pub fn load_options(&self, array_limit: Option<ArrayLimit>) -> LoadOptions {
        LoadOptions {
            scene: self.scene_index,
            environment: self.env.as_ref().and_then(EnvArg::constant),
            environment_map: self.env.as_ref().and_then(EnvArg::file),
            env_rotation: self.env_rotation,
            no_environment: self.env == Some(EnvArg::None),
            array_limit,
        }
    }
}

/// Path length, camera and seed: what every rendering command asks of a path.
#[derive(Args, Debug, Clone)]
pub struct PathArgs {
    /// Maximum number of path segments: 1 shows only directly visible emitters, 2 adds direct
    /// lighting, each further step adds one bounce of indirect light (ReSTIR PT: at most 7).
    #[arg(long, default_value_t = RenderSettings::DEFAULT_MAX_DEPTH)]
    pub max_depth: u32,
    /// Index of the glTF camera to render from (scene order); with a moving camera, its first
    /// pose.
    #[arg(long, default_value_t = 0)]
    pub camera: usize,
    /// Seed of the random numbers; runs of the same seed and settings are identical.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Russian roulette from the path's third vertex on (survival = the largest channel of its
    /// throughput, at most 0.95): the path tracer's paths and ReSTIR PT's initial candidates,
    /// never its shifts.
    #[arg(long, value_enum, default_value = "on")]
    pub russian_roulette: Toggle,
}

/// Image size with fixed defaults (`render` has its own: a missing side follows the camera).
#[derive(Args, Debug, Clone)]
pub struct SizeArgs {
    /// Image width in pixels.
    #[arg(long, default_value_t = RenderSettings::DEFAULT_WIDTH)]
    pub width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = RenderSettings::DEFAULT_HEIGHT)]
    pub height: u32,
}

/// `--plan`, `--job` and `--merge` of the sweep commands (see sweep.rs).
#[derive(Args, Debug, Clone, Default)]
pub struct SweepArgs {
    /// Write the runs as a job list (JSON lines: each job's command and working folder) to
    /// this file and run nothing; see tools/cluster/.
    #[arg(long, value_name = "JOBS.jsonl")]
    pub plan: Option<PathBuf>,
    /// Run only job K (0-based) of the job list these arguments make; it writes
    /// OUT_DIR/jobs/job_K.csv/.json.
    #[arg(long, value_name = "K")]
    pub job: Option<usize>,
    /// Merge the jobs' files in DIR (normally OUT_DIR/jobs) into the usual outputs and
    /// accounting.csv.
    #[arg(long, value_name = "DIR")]
    pub merge: Option<PathBuf>,
}

impl SweepArgs {
    /// One process for everything, or a job list, one job of it, or the merge of its jobs.
    pub fn mode(&self) -> Result<SweepMode> {
        SweepMode::from_flags(self.plan.clone(), self.job, self.merge.clone())
    }
}

/// Parses `argv` (the options alone, without a program or command name) into a command's
/// options, as the command line would: for tests and tools that call a command directly.
pub fn parse_args<T: Args>(argv: &[&str]) -> Result<T> {
    #[derive(clap::Parser)]
    struct Wrapper<T: Args> {
        #[command(flatten)]
        inner: T,
    }
    let argv = std::iter::once("restir-pt").chain(argv.iter().copied());
    Ok(<Wrapper<T> as clap::Parser>::try_parse_from(argv)?.inner)
}

/// The command line after the program name, for job lists.
pub fn argv() -> Vec<String> {
    std::env::args_os().skip(1).map(|a| a.to_string_lossy().into_owned()).collect()
}

/// `--exposure`: `auto` or an EV between -64 and 64.
pub fn parse_exposure(s: &str) -> Result<Exposure, String> {
    if s == "auto" {
        return Ok(Exposure::Auto);
    }
    match s.parse::<f32>() {
        Ok(ev) if ev.is_finite() && ev.abs() <= 64.0 => Ok(Exposure::Ev(ev)),
        _ => Err(format!("{s:?} is neither auto nor an EV between -64 and 64")),
    }
}

/// `--env`: a constant radiance or an environment map file.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvArg {
    Constant(Vec3),
    File(PathBuf),
    /// `--env none`: no environment, not even the default one.
    None,
}

impl EnvArg {
    pub fn constant(&self) -> Option<Vec3> {
        match self {
            EnvArg::Constant(c) => Some(*c),
            EnvArg::File(_) | EnvArg::None => None,
        }
    }

    pub fn file(&self) -> Option<PathBuf> {
        match self {
            EnvArg::File(f) => Some(f.clone()),
            EnvArg::Constant(_) | EnvArg::None => None,
        }
    }
}

/// `--env`: `none`, FILE.exr or FILE.hdr (by extension, any case), else R,G,B radiances.
pub fn parse_env(s: &str) -> Result<EnvArg, String> {
    let lower = s.to_ascii_lowercase();
    if lower.trim() == "none" {
        return Ok(EnvArg::None);
    }
    if lower.ends_with(".exr") || lower.ends_with(".hdr") {
        return Ok(EnvArg::File(PathBuf::from(s)));
    }
    parse_radiance(s).map(EnvArg::Constant)
}

/// R,G,B radiances; each error names the value and its first problem (negative values included:
/// the option takes hyphen values so that `--env -1,0,0` reaches this check, not clap's).
fn parse_radiance(s: &str) -> Result<Vec3, String> {
    const USAGE: &str = "--env takes R,G,B (three finite, non-negative radiances), FILE.exr|FILE.hdr or none";
    if s.trim().is_empty() {
        return Err(format!("the value is empty; {USAGE}"));
    }
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        let looks_like_file = s.contains('/')
            || s.rsplit_once('.')
                .is_some_and(|(_, ext)| ext.chars().any(|c| c.is_ascii_alphabetic()));
        return Err(if looks_like_file {
            format!("{s:?}: environment maps are read from .exr or .hdr files; {USAGE}")
        } else {
            format!("{s:?} has {} value(s); {USAGE}", parts.len())
        });
    }
    let mut rgb = [0.0f32; 3];
    for (value, part) in rgb.iter_mut().zip(&parts) {
        *value = part.parse().map_err(|_| format!("{s:?}: {part:?} is not a number; {USAGE}"))?;
        if !value.is_finite() {
            return Err(format!("{s:?}: {part} is not a finite f32 radiance; {USAGE}"));
        }
        if *value < 0.0 {
            return Err(format!("{s:?}: {part} is negative; {USAGE}"));
        }
    }
    Ok(Vec3::from_array(rgb))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn env_parses_radiance_and_files_and_refuses_negative_radiance() {
        assert_eq!(parse_env("1, 0.5,0"), Ok(EnvArg::Constant(Vec3::new(1.0, 0.5, 0.0))));
        assert_eq!(parse_env("sky.HDR"), Ok(EnvArg::File("sky.HDR".into())));
        assert_eq!(parse_env("none"), Ok(EnvArg::None));
        assert_eq!(parse_degrees("-90"), Ok(-90.0));
        assert!(parse_degrees("inf").is_err() && parse_degrees("east").is_err());
        for bad in ["-1,0,0", "1,2", "1,2,inf", "x,y,z"] {
            assert!(parse_env(bad).is_err(), "{bad}");
        }
    }

    #[derive(clap::Parser)]
    struct Restir {
        #[command(flatten)]
        restir: RestirArgs,
    }

    #[test]
    fn restir_flag_defaults_are_the_library_defaults_and_changes_are_named() {
        use clap::Parser;
        let defaults = Restir::parse_from(["t"]).restir;
        assert_eq!(defaults.settings(), RestirSettings::default());
        assert!(defaults.changed_flags().is_empty());
        let set = Restir::parse_from(["t", "--shift", "replay", "--temporal", "off", "--mis", "gbh", "--radius", "-2"]).restir;
        assert_eq!(set.changed_flags(), ["--shift replay", "--temporal off", "--radius -2"]);
    }
}
