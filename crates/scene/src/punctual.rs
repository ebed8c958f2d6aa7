//! `KHR_lights_punctual`: point, spot and directional lights in scene coordinates, with the
//! extension's units (point and spot intensity in candela, directional in lux).

use anyhow::{bail, Result};
use glam::{DMat4, DVec3, Vec3};

use restir_pt_interface::gpu_types::Emitter;

use super::gltf_loader::{problem, Loader};
use super::luminance;

/// The kind of a punctual light; the values are those of glsl/interface/types.glsl.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PunctualKind {
    /// Emits the same intensity in every direction from `position`.
    Point = 0,
    /// A point light restricted to a cone around `direction`, with a smooth edge between the inner
    /// and outer angles (a hard edge where they are equal, as Blender writes a spot of blend 0).
    Spot = 1,
    /// Parallel light along `direction` from infinitely far away, e.g. the sun.
    Directional = 2,
}

/// A punctual light in scene coordinates (world space moved by -`Scene::origin`). Radiometry:
/// the renderer's radiance unit is the glTF emission unit (1 nit), so a point or spot light of
/// `intensity` I (candela, times `color`) gives irradiance I·cosθ/d² at distance d, and a
/// directional light of I (lux) gives irradiance I·cosθ everywhere (KHR_lights_punctual,
/// "Units").
#[derive(Debug, Clone, PartialEq)]
pub struct PunctualLight {
    /// Point, spot or directional.
    pub kind: PunctualKind,
    /// Position (point and spot) relative to `Scene::origin`, unused for directional lights.
    pub position: Vec3,
    /// Unit direction the light shines along (spot and directional; the node's -Z).
    pub direction: Vec3,
    /// colour × intensity: radiant intensity (point, spot) or irradiance (directional).
    pub intensity: Vec3,
    /// Cosine of the spot cone's inner angle, inside which the light is at full intensity (1 for
    /// other kinds).
    pub cos_inner: f32,
    /// Cosine of the spot cone's outer angle, outside which it emits nothing (-1 for other kinds).
    pub cos_outer: f32,
}

impl Loader<'_> {
    /// Adds the light of `node` with world transform `world`; its position is kept in f64 world
    /// space (`light_positions`) until the walk has chosen the scene's origin.
    pub(super) fn add_light(&mut self, light: &gltf::khr_lights_punctual::Light, node: &gltf::Node, world: &DMat4) -> Result<()> {
        use gltf::khr_lights_punctual::Kind;
        let colour = Vec3::from(light.color());
        let intensity = light.intensity();
        if !colour.is_finite() || colour.min_element() < 0.0 || !intensity.is_finite() || intensity < 0.0 {
            bail!(problem(
                self.path,
                format!(
                    "light on node {}: color and intensity must be finite and non-negative",
                    node.index()
                )
            ));
        }
        if light.range().is_some() {
            self.warn("KHR_lights_punctual range ignored: lights fall off with the inverse square of distance");
        }
        let (kind, cos_inner, cos_outer) = match light.kind() {
            Kind::Point => (PunctualKind::Point, 1.0, -1.0),
            Kind::Directional => (PunctualKind::Directional, 1.0, -1.0),
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                // Blender writes inner = outer for a spot of blend 0; viewers draw a hard edge.
                let hard_edge = inner_cone_angle == outer_cone_angle;
                let ok = (0.0..=std::f32::consts::FRAC_PI_2).contains(&outer_cone_angle)
                    && (hard_edge || (0.0..outer_cone_angle.max(f32::MIN_POSITIVE)).contains(&inner_cone_angle));
                if !ok {
                    bail!(problem(
                        self.path,
                        format!(
                            "spot light on node {}: cone angles must satisfy 0 <= inner < outer <= pi/2 (inner {inner_cone_angle}, outer {outer_cone_angle})",
                            node.index()
                        )
                    ));
                }
                if hard_edge {
                    self.warn(format!(
                        "spot light on node {}: innerConeAngle equals outerConeAngle ({outer_cone_angle}); the schema asks inner < outer, drawn as a hard-edged cone",
                        node.index()
                    ));
                }
                (PunctualKind::Spot, inner_cone_angle.cos(), outer_cone_angle.cos())
            }
        };
        let direction = world.transform_vector3(-DVec3::Z).normalize().as_vec3();
        if !direction.is_finite() {
            bail!(problem(
                self.path,
                format!("light on node {} has a degenerate transform", node.index())
            ));
        }
        if luminance(colour * intensity) > 0.0 {
            self.light_positions.push(world.transform_point3(DVec3::ZERO));
            self.lights.push(PunctualLight {
                kind,
                position: Vec3::ZERO,
                direction,
                intensity: colour * intensity,
                cos_inner,
                cos_outer,
            });
        }
        Ok(())
    }
}

/// The emitter-buffer rows of punctual lights (`emitter_rows[k]`: the row of light k among the
/// [`Emitter`]s), reinterpreting each 16-byte row as four 32-bit words.
pub(crate) fn punctual_rows(lights: &[PunctualLight], emitter_rows: &[u32]) -> Vec<Emitter> {
    let row = |a: [f32; 3], w: u32| Emitter::from_words([a[0].to_bits(), a[1].to_bits(), a[2].to_bits(), w]);
    lights
        .iter()
        .zip(emitter_rows)
        .flat_map(|(l, &r)| {
            [
                row(l.position.into(), l.kind as u32),
                row(l.direction.into(), l.cos_outer.to_bits()),
                row(l.intensity.into(), l.cos_inner.to_bits()),
                Emitter::from_words([r, 0, 0, 0]),
            ]
        })
        .collect()
}
