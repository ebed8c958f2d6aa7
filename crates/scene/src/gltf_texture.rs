//! glTF textures, images and samplers to [`SceneTextures`]: PNG and JPEG images decoded (with
//! the `image` crate, through gltf's importer) to RGBA8, one header per glTF texture (image and
//! sampler), and per material its texture slots with `KHR_texture_transform` folded in.
//! `occlusionTexture` is not read: a path tracer computes the occlusion it approximates.

use std::collections::HashMap;

use anyhow::{bail, Result};

use restir_pt_shading_core::texture::{
    texture_transform_rows, MaterialTextures, SceneTextures, TextureHeader, TextureSlot, NO_TEXTURE, TEXTURE_NEAREST, TEXTURE_WRAP_CLAMP,
    TEXTURE_WRAP_MIRROR, TEXTURE_WRAP_REPEAT,
};

use super::gltf_loader::{problem, Loader};

/// Textures larger than this on a side are halved until they fit (mipmaps are not built, so
/// larger ones would alias anyway at the resolutions rendered here).
pub const MAX_TEXTURE_SIDE: u32 = 4096;

/// The texture slots of one glTF material, as (texture, texCoord, transform) references.
struct SlotRef<'a> {
    texture: gltf::Texture<'a>,
    tex_coord: u32,
    transform: Option<gltf::texture::TextureTransform<'a>>,
}

fn slot_ref<'a>(info: Option<gltf::texture::Info<'a>>) -> Option<SlotRef<'a>> {
    info.map(|i| SlotRef {
        texture: i.texture(),
        tex_coord: i.tex_coord(),
        transform: i.texture_transform(),
    })
}

/// The normal texture's reference; gltf's `NormalTexture` does not expose the extension, so it
/// is read from the JSON.
fn normal_ref<'a>(m: &gltf::Material<'a>) -> Option<(SlotRef<'a>, f32)> {
    let n = m.normal_texture()?;
    Some((
        SlotRef {
            texture: n.texture(),
            tex_coord: n.tex_coord(),
            transform: None,
        },
        n.scale(),
    ))
}

/// KHR_texture_transform's (offset, rotation, scale, texCoord override).
pub(super) type UvTransform = ([f32; 2], f32, [f32; 2], Option<u32>);

/// `KHR_texture_transform` of a normal texture from its JSON: (offset, rotation, scale, texCoord).
pub(super) fn normal_transform(m: &gltf::Material) -> Option<UvTransform> {
    let json = m.normal_texture()?.extension_value("KHR_texture_transform")?.clone();
    let pair = |k: &str, d: [f32; 2]| {
        json.get(k)
            .and_then(|v| v.as_array())
            .filter(|a| a.len() == 2)
            .and_then(|a| Some([a[0].as_f64()? as f32, a[1].as_f64()? as f32]))
            .unwrap_or(d)
    };
    let rotation = json.get("rotation").and_then(|v| v.as_f64()).unwrap_or(0.0) as f32;
    let tex_coord = json.get("texCoord").and_then(|v| v.as_u64()).map(|v| v as u32);
    Some((pair("offset", [0.0, 0.0]), rotation, pair("scale", [1.0, 1.0]), tex_coord))
}

impl Loader<'_> {
    /// Whether any material uses a texture this renderer reads, or is not opaque.
    pub(super) fn materials_use_textures(&self) -> bool {
        self.doc.materials().any(|m| {
            let pbr = m.pbr_metallic_roughness();
            pbr.base_color_texture().is_some()
                || pbr.metallic_roughness_texture().is_some()
                || m.emissive_texture().is_some()
                || m.normal_texture().is_some()
                || m.alpha_mode() != gltf::material::AlphaMode::Opaque
        })
    }

    /// The scene's textures (empty when no material uses one): images decoded once each,
    /// within `max_bytes` of texels. Materials past the file's (the default material) copy
    /// their source's slots via `material_sources`.
    pub(super) fn load_textures(&mut self, material_sources: &[Option<usize>], max_bytes: u64) -> Result<SceneTextures> {
        if !self.materials_use_textures() {
            return Ok(SceneTextures::default());
        }
        let doc = self.doc;
        let mut out = SceneTextures::default();
        let mut headers: HashMap<usize, u32> = HashMap::new();
        let mut per_material = Vec::new();
        for m in doc.materials() {
            per_material.push(self.material_textures(&m, &mut headers, &mut out)?);
        }
        out.materials = material_sources
            .iter()
            .map(|s| {
                s.map(|i| per_material[i]).unwrap_or(MaterialTextures {
                    normal_scale: 1.0,
                    alpha_cutoff: 0.5,
                    base_alpha: 1.0,
                    ..Default::default()
                })
            })
            .collect();
        let bytes = out.texels.len() as u64 * 4;
        if bytes > max_bytes {
            bail!(problem(
                self.path,
                format!("the textures need {bytes} bytes, more than the device binds at once ({max_bytes})")
            ));
        }
        Ok(out)
    }

    /// The texture slots and alpha state of material `m`; images not yet in `headers` (glTF
    /// texture index to header index) are decoded into `out`.
    fn material_textures(
        &mut self,
        m: &gltf::Material,
        headers: &mut HashMap<usize, u32>,
        out: &mut SceneTextures,
    ) -> Result<MaterialTextures> {
        let pbr = m.pbr_metallic_roughness();
        let (alpha_mode, alpha_cutoff) = self.alpha_test(m);
        let mut t = MaterialTextures {
            normal_scale: 1.0,
            alpha_cutoff,
            alpha_mode,
            base_alpha: pbr.base_color_factor()[3].clamp(0.0, 1.0),
            ..Default::default()
        };
        let mut refs = [
            slot_ref(pbr.base_color_texture()),
            slot_ref(pbr.metallic_roughness_texture()),
            slot_ref(m.emissive_texture()),
            None,
        ];
        let mut normal_xf = None;
        if let Some((r, scale)) = normal_ref(m) {
            refs[3] = Some(r);
            t.normal_scale = scale;
            normal_xf = normal_transform(m);
        }
        for (k, r) in refs.iter().enumerate() {
            let Some(r) = r else { continue };
            let header = match headers.get(&r.texture.index()) {
                Some(&h) => h,
                None => {
                    let h = self.add_texture(&r.texture, out)?;
                    headers.insert(r.texture.index(), h);
                    h
                }
            };
            // A missing image file leaves the slot empty: the factor alone, as viewers draw it.
            if header == NO_TEXTURE {
                continue;
            }
            // The normal texture's transform comes from the extension gltf does not expose.
            let fallback = if k == 3 { normal_xf } else { None };
            let slot = self.texture_slot(r, header, fallback);
            match k {
                0 => t.base_color = slot,
                1 => t.metal_rough = slot,
                2 => t.emissive = slot,
                _ => t.normal = slot,
            }
        }
        Ok(t)
    }

    /// The slot of texture reference `r` whose image is header `header`; `fallback` is the
    /// transform used when `r` carries none.
    fn texture_slot(&mut self, r: &SlotRef, header: u32, fallback: Option<UvTransform>) -> TextureSlot {
        let (offset, rotation, scale, tex_coord) = match &r.transform {
            Some(x) => (x.offset(), x.rotation(), x.scale(), x.tex_coord()),
            None => fallback.unwrap_or(([0.0; 2], 0.0, [1.0; 2], None)),
        };
        let set = tex_coord.unwrap_or(r.tex_coord);
        if set > 1 {
            self.warn(format!(
                "texture {} uses TEXCOORD_{set}; only sets 0 and 1 are read, 0 used",
                r.texture.index()
            ));
        }
        let (u_row, v_row) = texture_transform_rows(offset, rotation, scale);
        TextureSlot {
            u_row,
            texture_index: header,
            v_row,
            texcoord: if set == 1 { 1 } else { 0 },
        }
    }

    /// Decodes the image of `texture` into `out` with its sampler; returns its header's index, or
    /// `NO_TEXTURE` (with a warning) for an external image file that cannot be read.
    fn add_texture(&mut self, texture: &gltf::Texture, out: &mut SceneTextures) -> Result<u32> {
        let path = self.path;
        let image = texture
            .source()
            .ok_or_else(|| problem(path, format!("texture {} has no image", texture.index())))?;
        if let gltf::image::Source::View { view, .. } = image.source() {
            let len = self.buffers.get(view.buffer().index()).map_or(0, |b| b.0.len());
            if view.offset() + view.length() > len {
                bail!(problem(
                    path,
                    format!("image {}: its buffer view lies outside its buffer", image.index())
                ));
            }
        }
        // Embedded (data:) images need no folder; gltf's importer wants one all the same.
        let base = match image.source() {
            gltf::image::Source::Uri { uri, .. } if uri.starts_with("data:") => Some(self.base.unwrap_or(std::path::Path::new("."))),
            _ => self.base,
        };
        let data = gltf::image::Data::from_source(
            image.source(),
            base.or(Some(std::path::Path::new(".")))
                .filter(|_| base.is_some() || !matches!(image.source(), gltf::image::Source::Uri { .. })),
            self.buffers,
        );
        if let (Err(gltf::Error::Io(e)), gltf::image::Source::Uri { uri, .. }) = (&data, image.source()) {
            if !uri.starts_with("data:") {
                self.warn(format!(
                    "image {} ({uri}) cannot be read ({e}): the materials using texture {} take their factors alone",
                    image.index(),
                    texture.index()
                ));
                return Ok(NO_TEXTURE);
            }
        }
        let data = data.map_err(|e| {
            let what = match image.source() {
                gltf::image::Source::Uri { uri, .. } if !uri.starts_with("data:") => format!("image {} ({uri})", image.index()),
                _ => format!("image {}", image.index()),
            };
            problem(path, format!("{what}: cannot read or decode: {e}"))
        })?;
        let mut rgba =
            to_rgba8(&data).ok_or_else(|| problem(path, format!("image {}: unsupported pixel format {:?}", image.index(), data.format)))?;
        while rgba.width() > MAX_TEXTURE_SIDE || rgba.height() > MAX_TEXTURE_SIDE {
            let (w, h) = ((rgba.width() / 2).max(1), (rgba.height() / 2).max(1));
            self.warn(format!(
                "image {}: {}x{} halved to {w}x{h}",
                image.index(),
                rgba.width(),
                rgba.height()
            ));
            rgba = image::imageops::resize(&rgba, w, h, image::imageops::FilterType::Triangle);
        }
        let sampler = texture.sampler();
        let wrap = |m: gltf::texture::WrappingMode| match m {
            gltf::texture::WrappingMode::ClampToEdge => TEXTURE_WRAP_CLAMP,
            gltf::texture::WrappingMode::MirroredRepeat => TEXTURE_WRAP_MIRROR,
            gltf::texture::WrappingMode::Repeat => TEXTURE_WRAP_REPEAT,
        };
        let nearest = sampler.mag_filter() == Some(gltf::texture::MagFilter::Nearest);
        out.headers.push(TextureHeader {
            width: rgba.width(),
            height: rgba.height(),
            offset: out.texels.len() as u32,
            sampler_bits: wrap(sampler.wrap_s()) | (wrap(sampler.wrap_t()) << 2) | if nearest { TEXTURE_NEAREST } else { 0 },
        });
        out.texels.extend(rgba.pixels().map(|p| u32::from_le_bytes(p.0)));
        Ok(out.headers.len() as u32 - 1)
    }
}

/// Decoded pixels as RGBA8 (16-bit channels keep their high byte; grey fills RGB; opaque alpha
/// where there is none).
fn to_rgba8(data: &gltf::image::Data) -> Option<image::RgbaImage> {
    use gltf::image::Format;
    let (channels, bytes) = match data.format {
        Format::R8 => (1, 1),
        Format::R8G8 => (2, 1),
        Format::R8G8B8 => (3, 1),
        Format::R8G8B8A8 => (4, 1),
        Format::R16 => (1, 2),
        Format::R16G16 => (2, 2),
        Format::R16G16B16 => (3, 2),
        Format::R16G16B16A16 => (4, 2),
        _ => return None,
    };
    let stride = channels * bytes;
    let pixels = (data.width * data.height) as usize;
    if data.pixels.len() < pixels * stride {
        return None;
    }
    let mut out = Vec::with_capacity(pixels * 4);
    for p in data.pixels.chunks_exact(stride).take(pixels) {
        // Little-endian 16-bit channels: the high byte is the second.
        let ch = |k: usize| p[k * bytes + bytes - 1];
        let rgba = match channels {
            1 => [ch(0), ch(0), ch(0), 255],
            2 => [ch(0), ch(0), ch(0), ch(1)],
            3 => [ch(0), ch(1), ch(2), 255],
            _ => [ch(0), ch(1), ch(2), ch(3)],
        };
        out.extend(rgba);
    }
    image::RgbaImage::from_raw(data.width, data.height, out)
}
