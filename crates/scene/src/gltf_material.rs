//! glTF materials to [`Material`]: metallic-roughness factors, emission, transmission,
//! `KHR_materials_specular`, and the
//! approximations for `KHR_materials_unlit`, `KHR_materials_pbrSpecularGlossiness` and COLOR_0.

use anyhow::{bail, Result};
use glam::Vec3;

use restir_pt_interface::gpu_types::{Material, MATERIAL_ALPHA_EMISSION, MATERIAL_BLEND_EMISSION, MATERIAL_DOUBLE_SIDED, MATERIAL_UNLIT};
use restir_pt_shading_core::texture::{ALPHA_BLEND, ALPHA_MASK, ALPHA_OPAQUE};

use super::gltf_loader::{problem, Loader};

/// Specular reflectance at normal incidence of dielectrics in the metallic-roughness model.
const DIELECTRIC_F0: f32 = 0.04;

/// Perceived brightness of a colour, as the Khronos spec-gloss conversion example weighs it.
fn perceived_brightness(c: Vec3) -> f32 {
    (0.299 * c.x * c.x + 0.587 * c.y * c.y + 0.114 * c.z * c.z).sqrt()
}

/// The metallic factor whose mix of a dielectric and a conductor best matches the diffuse and
/// specular brightness: the root of a quadratic in `metallic` (Khronos glTF sample
/// "convert-between-workflows", `solveMetallic`).
fn solve_metallic(diffuse: f32, specular: f32, one_minus_specular_strength: f32) -> f32 {
    if specular < DIELECTRIC_F0 {
        return 0.0;
    }
    let a = DIELECTRIC_F0;
    let b = diffuse * one_minus_specular_strength / (1.0 - DIELECTRIC_F0) + specular - 2.0 * DIELECTRIC_F0;
    let c = DIELECTRIC_F0 - specular;
    let d = (b * b - 4.0 * a * c).max(0.0);
    ((-b + d.sqrt()) / (2.0 * a)).clamp(0.0, 1.0)
}

/// Specular-glossiness factors to (base colour, metallic, roughness), approximately: roughness is
/// 1 - glossiness, metallic solves `solve_metallic`, and the base colour blends the colour
/// implied by the diffuse term with the one implied by the specular term by metallic².
pub fn spec_gloss_to_metal_rough(diffuse: Vec3, specular: Vec3, glossiness: f32) -> (Vec3, f32, f32) {
    let one_minus = 1.0 - specular.max_element();
    let metallic = solve_metallic(perceived_brightness(diffuse), perceived_brightness(specular), one_minus);
    let from_diffuse = diffuse * (one_minus / (1.0 - DIELECTRIC_F0) / (1.0 - metallic).max(1e-4));
    let from_specular = (specular - Vec3::splat(DIELECTRIC_F0 * (1.0 - metallic))) / metallic.max(1e-4);
    let base = from_diffuse.lerp(from_specular, metallic * metallic);
    (base.clamp(Vec3::ZERO, Vec3::ONE), metallic, (1.0 - glossiness).clamp(0.0, 1.0))
}

/// The cutoff of a BLEND emitter traversed as MASK: below half of 8-bit alpha's first step, so
/// that every texel with alpha > 0 is there.
pub const EMISSIVE_BLEND_CUTOFF: f32 = 0.5 / 255.0;

/// Whether `m` emits (an emissive factor with a positive strength, or unlit).
fn emits(m: &gltf::Material) -> bool {
    m.unlit() || m.emissive_factor().iter().any(|&c| c > 0.0) && m.emissive_strength().unwrap_or(1.0) > 0.0
}

/// The flags by which an emitter's alpha mode weights its emission: `MATERIAL_ALPHA_EMISSION`
/// for MASK and BLEND, `MATERIAL_BLEND_EMISSION` too for BLEND; 0 otherwise.
fn emitter_alpha_flags(m: &gltf::Material) -> u32 {
    use gltf::material::AlphaMode;
    match m.alpha_mode() {
        AlphaMode::Mask if emits(m) => MATERIAL_ALPHA_EMISSION,
        AlphaMode::Blend if emits(m) => MATERIAL_ALPHA_EMISSION | MATERIAL_BLEND_EMISSION,
        _ => 0,
    }
}

impl Loader<'_> {
    /// The alpha mode (`ALPHA_*`) and cutoff traversal applies to material `m`. An emitter
    /// keeps MASK; a BLEND emitter is traversed as MASK at [`EMISSIVE_BLEND_CUTOFF`] (present
    /// where alpha > 0) and emits alpha × its emission ([`emitter_alpha_flags`]), so that every
    /// estimator, light samples included, sees the same coverage.
    /// A cutoff outside [0, 1] is usable (below 0 every hit counts, above 1 none does) and warned
    /// about; it is kept as written.
    pub(super) fn alpha_test(&mut self, m: &gltf::Material) -> (u32, f32) {
        use gltf::material::AlphaMode;
        let name = m
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("material {}", m.index().unwrap_or(0)));
        let cutoff = m.alpha_cutoff().unwrap_or(0.5);
        let mode = m.alpha_mode();
        if mode == AlphaMode::Opaque {
            return (ALPHA_OPAQUE, cutoff);
        }
        if mode == AlphaMode::Blend && emits(m) {
            return (ALPHA_MASK, EMISSIVE_BLEND_CUTOFF);
        }
        if mode == AlphaMode::Blend {
            return (ALPHA_BLEND, cutoff);
        }
        if !(0.0..=1.0).contains(&cutoff) {
            let effect = if cutoff > 1.0 {
                "no part of it is rendered"
            } else {
                "it is rendered opaque"
            };
            self.warn(format!("{name}: alphaCutoff {cutoff} is outside [0, 1]; {effect}"));
        }
        (ALPHA_MASK, cutoff)
    }

    pub(super) fn load_materials(&mut self) -> Result<()> {
        let doc = self.doc;
        let mut spec_gloss = 0;
        for m in doc.materials() {
            let name = m
                .name()
                .map(str::to_string)
                .unwrap_or_else(|| format!("material {}", m.index().unwrap_or(0)));
            spec_gloss += m.pbr_specular_glossiness().is_some() as usize;
            let material = self.convert_material(&m, &name)?;
            self.materials.push(material);
            self.material_names.push(name);
            self.material_sources.push(m.index());
            self.unlit.push(m.unlit());
        }
        let unlit = self.unlit.iter().filter(|&&u| u).count();
        if unlit > 0 {
            self.warn(format!(
                "{unlit} KHR_materials_unlit material(s) rendered as emission of their base colour (no reflection)"
            ));
        }
        if spec_gloss > 0 {
            self.warn(format!(
                "{spec_gloss} KHR_materials_pbrSpecularGlossiness material(s) converted to metallic-roughness approximately"
            ));
        }
        Ok(())
    }

    fn warn_ignored_textures(&mut self, m: &gltf::Material, name: &str) {
        let pbr = m.pbr_metallic_roughness();
        let sg = m.pbr_specular_glossiness();
        // The occlusion texture is not read and not reported: it approximates the occlusion that
        // path tracing computes.
        let _ = &pbr;
        let ignored_textures = [
            ("transmission", m.transmission().is_some_and(|t| t.transmission_texture().is_some())),
            ("specular", m.specular().is_some_and(|s| s.specular_texture().is_some())),
            (
                "specular colour",
                m.specular().is_some_and(|s| s.specular_color_texture().is_some()),
            ),
            ("diffuse", sg.as_ref().is_some_and(|s| s.diffuse_texture().is_some())),
            (
                "specular-glossiness",
                sg.as_ref().is_some_and(|s| s.specular_glossiness_texture().is_some()),
            ),
        ];
        for (kind, present) in ignored_textures {
            if present {
                self.warn(format!("{name}: {kind} texture ignored (its factor is used)"));
            }
        }
    }

    fn convert_material(&mut self, m: &gltf::Material, name: &str) -> Result<Material> {
        self.warn_ignored_textures(m, name);
        if m.volume().is_some() {
            self.warn(format!("{name}: KHR_materials_volume ignored (no participating media)"));
        }
        let pbr = m.pbr_metallic_roughness();
        let (mut base, mut metallic, mut roughness) = (
            Vec3::from_slice(&pbr.base_color_factor()[..3]),
            pbr.metallic_factor(),
            pbr.roughness_factor(),
        );
        if let Some(sg) = m.pbr_specular_glossiness() {
            let diffuse = Vec3::from_slice(&sg.diffuse_factor()[..3]);
            (base, metallic, roughness) = spec_gloss_to_metal_rough(diffuse, Vec3::from(sg.specular_factor()), sg.glossiness_factor());
        }
        let strength = m.emissive_strength().unwrap_or(1.0);
        let emissive = m.emissive_factor();
        let transmission = m.transmission().map(|t| t.transmission_factor()).unwrap_or(0.0);
        let ior = m.ior().unwrap_or(1.5);
        // KHR_materials_specular's defaults are the core spec's layer: strength 1, white F0 tint.
        let (specular, specular_color) = m
            .specular()
            .map(|s| (s.specular_factor(), Vec3::from(s.specular_color_factor())))
            .unwrap_or((1.0, Vec3::ONE));
        let checks = [
            (
                "baseColorFactor",
                base.is_finite() && base.min_element() >= 0.0 && base.max_element() <= 1.0,
            ),
            ("metallicFactor", (0.0..=1.0).contains(&metallic)),
            ("roughnessFactor", (0.0..=1.0).contains(&roughness)),
            ("emissiveFactor", emissive.iter().all(|v| v.is_finite() && *v >= 0.0)),
            ("emissiveStrength", strength.is_finite() && strength >= 0.0),
            ("transmissionFactor", (0.0..=1.0).contains(&transmission)),
            ("specularFactor", (0.0..=1.0).contains(&specular)),
            (
                "specularColorFactor",
                specular_color.is_finite() && specular_color.min_element() >= 0.0,
            ),
            // Within rounding below 1 is index-matched (docs/materials.md), not an error.
            (
                "ior",
                ior.is_finite() && (ior >= 1.0 || restir_pt_shading_core::bsdf::index_matched(ior)),
            ),
        ];
        if let Some((field, _)) = checks.iter().find(|(_, ok)| !ok) {
            bail!(problem(self.path, format!("{name}: {field} is out of range or not a number")));
        }
        let flags = if m.double_sided() { MATERIAL_DOUBLE_SIDED } else { 0 } | emitter_alpha_flags(m);
        if m.unlit() {
            // An unlit surface shows its base colour whatever the lighting: emission, no BSDF.
            let flags = flags | MATERIAL_UNLIT;
            return Ok(Material {
                base_color: [0.0; 3],
                metallic: 0.0,
                emission: base.into(),
                roughness: 1.0,
                transmission: 0.0,
                ior: 1.5,
                flags,
                specular: 0.0,
                specular_color: [0.0; 3],
                pad: 0,
            });
        }
        Ok(Material {
            base_color: base.into(),
            metallic,
            emission: (Vec3::from(emissive) * strength).into(),
            roughness,
            transmission,
            ior,
            flags,
            specular,
            specular_color: specular_color.into(),
            pad: 0,
        })
    }

    pub(super) fn default_material(&mut self) -> u32 {
        *self.default_material.get_or_insert_with(|| {
            // glTF's default material: white, metallic 1, roughness 1.
            self.materials.push(Material {
                base_color: [1.0; 3],
                metallic: 1.0,
                roughness: 1.0,
                ior: 1.5,
                specular: 1.0,
                specular_color: [1.0; 3],
                ..Default::default()
            });
            self.material_names.push("glTF default material".to_string());
            self.material_sources.push(None);
            self.unlit.push(false);
            (self.materials.len() - 1) as u32
        })
    }
}
