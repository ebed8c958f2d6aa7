#!/usr/bin/env python3
"""Render a glTF file with Mitsuba 3 as an independent reference for restir-pt, and write its image
statistics (docs/independent-check.md).

The file is read here with pygltflib and numpy, not by restir-pt, so that a loader bug of either
side shows as a difference. The scene is what restir-pt renders for that file:

- meshes: every triangle primitive (lists, strips, fans; indexed or not; sparse accessors) of the
  scene's node tree, in world space, with NORMAL and the texture coordinate set the material's
  textures use; a mirroring node transform reverses the winding, as glTF asks;
- materials: glTF metallic-roughness as Mitsuba's `principled` BSDF (base_color, metallic,
  roughness; eta from KHR_materials_ior, spec_trans from KHR_materials_transmission), with
  textures as `bitmap`s: the base colour (sRGB, decoded here, times baseColorFactor), the
  metallic-roughness texture split into its B (metallic) and G (roughness) channels times their
  factors, KHR_texture_transform as the bitmap's `to_uv`, the sampler's wrap mode and filter;
  normalTexture through the `normalmap` BSDF (x and y scaled by `scale`); a non-metal with
  KHR_materials_specular specularFactor 0 (restir-pt's exact Lambertian) as `diffuse`;
- emission: emissiveFactor x KHR_materials_emissive_strength x emissiveTexture (sRGB) as an
  `area` emitter's radiance;
- lights and camera as restir-pt defaults them (docs/scenes.md): the constant environment of the
  scene's or the root's extras, else radiance 1 when the file has no emissive triangle and no
  punctual light; the first perspective camera in scene order, else the default camera that looks
  at the centre of the triangles' bounds along -(0, 1, 2)/sqrt(5) from r / sin(22.5 deg), yfov 45;
- the `path` integrator with restir-pt's --max-depth (segments; 1 = emitters seen directly), a
  box pixel filter (restir-pt jitters uniformly inside each pixel).

The image is rendered in `--passes` independent passes of spp / passes samples (seeds 0, 1, ...).
The JSON holds the settings, the mean RGB of the image and of each tile of a `--tiles` x `--tiles`
grid (row-major from the top-left), and each mean's standard error over the passes, so that a test
can tell Monte Carlo noise from a real difference.

    pip install mitsuba pygltflib numpy pillow
    python3 tools/mitsuba_reference.py ../shared/assets/BoxTextured/BoxTextured.gltf \\
        --width 64 --height 64 --spp 1024 --out out/mitsuba/BoxTextured.exr \\
        --json tests/data/independent/BoxTextured.json
"""
import argparse
import json
import math
import os
import sys
import time

import numpy as np

GL_REPEAT, GL_CLAMP, GL_MIRROR = 10497, 33071, 33648
GL_NEAREST = 9728
COMPONENT = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
DEFAULT_VIEW = np.array([0.0, 1.0, 2.0]) / math.sqrt(5.0)
DEFAULT_YFOV = math.pi / 4


def warn(msg):
    print("warning: " + msg, file=sys.stderr)


class Gltf:
    """The glTF document and its buffers, read with pygltflib."""

    def __init__(self, path, edits=()):
        import pygltflib
        self.path = path
        self.dir = os.path.dirname(os.path.abspath(path))
        if edits:
            with open(path, encoding="utf-8") as f:
                doc = json.load(f)
            for edit in edits:
                edit(doc)
            self.g = pygltflib.GLTF2.from_json(json.dumps(doc))
        else:
            self.g = pygltflib.GLTF2().load(path)
        self.buffers = [self._buffer(i, b) for i, b in enumerate(self.g.buffers)]
        self.image_cache = {}

    def _buffer(self, i, b):
        if b.uri is None:
            return self.g.binary_blob()
        if b.uri.startswith("data:"):
            import base64
            return base64.b64decode(b.uri.split(",", 1)[1])
        with open(os.path.join(self.dir, b.uri), "rb") as f:
            return f.read()

    def _view(self, index, count, dtype, width, byte_offset=0):
        view = self.g.bufferViews[index]
        start = (view.byteOffset or 0) + byte_offset
        item = np.dtype(dtype).itemsize * width
        stride = view.byteStride or item
        blob = self.buffers[view.buffer]
        rows = np.frombuffer(blob, np.uint8, count=(count - 1) * stride + item if count else 0, offset=start)
        if count == 0:
            return np.zeros((0, width), dtype)
        strided = np.lib.stride_tricks.as_strided(rows, shape=(count, item), strides=(stride, 1))
        return np.ascontiguousarray(strided).view(dtype).reshape(count, width)

    def accessor(self, index):
        """The accessor's elements as float64 (normalised integers scaled to [0, 1] or [-1, 1]),
        shape (count, components); sparse substitutions applied."""
        a = self.g.accessors[index]
        dtype, width = COMPONENT[a.componentType], WIDTH[a.type]
        if a.bufferView is None:
            data = np.zeros((a.count, width), dtype)
        else:
            data = self._view(a.bufferView, a.count, dtype, width, a.byteOffset or 0).copy()
        if a.sparse is not None and a.sparse.count:
            s = a.sparse
            idx = self._view(s.indices.bufferView, s.count, COMPONENT[s.indices.componentType], 1,
                             s.indices.byteOffset or 0)[:, 0]
            data[idx.astype(np.int64)] = self._view(s.values.bufferView, s.count, dtype, width, s.values.byteOffset or 0)
        out = data.astype(np.float64)
        if a.normalized and dtype != np.float32:
            info = np.iinfo(dtype)
            out = np.maximum(out / info.max, -1.0)
        return out

    def image_rgba(self, image_index):
        """The image's RGBA as float32 in [0, 1], shape (h, w, 4), cached."""
        if image_index in self.image_cache:
            return self.image_cache[image_index]
        from PIL import Image
        import io
        img = self.g.images[image_index]
        if img.uri is not None and img.uri.startswith("data:"):
            import base64
            raw = base64.b64decode(img.uri.split(",", 1)[1])
        elif img.uri is not None:
            from urllib.parse import unquote
            with open(os.path.join(self.dir, unquote(img.uri)), "rb") as f:
                raw = f.read()
        else:
            view = self.g.bufferViews[img.bufferView]
            start = view.byteOffset or 0
            raw = self.buffers[view.buffer][start:start + view.byteLength]
        pixels = np.asarray(Image.open(io.BytesIO(raw)).convert("RGBA"), np.float32) / 255.0
        self.image_cache[image_index] = pixels
        return pixels


def make_lambertian(doc):
    """Every material a Lambertian of its base colour, as restir-pt reads it: metallic 0, no
    metallic-roughness texture, KHR_materials_specular specularFactor 0 (normal, emissive and base
    colour textures stay)."""
    for m in doc.get("materials", []):
        pbr = m.setdefault("pbrMetallicRoughness", {})
        pbr["metallicFactor"] = 0.0
        pbr.pop("metallicRoughnessTexture", None)
        m.setdefault("extensions", {})["KHR_materials_specular"] = {"specularFactor": 0.0}
    used = doc.setdefault("extensionsUsed", [])
    if "KHR_materials_specular" not in used:
        used.append("KHR_materials_specular")


def make_emissive(doc):
    """Every material with a base colour texture emits it instead: emissiveTexture the same
    textureInfo (coordinate set and transform included), emissiveFactor 1, base colour black."""
    for m in doc.get("materials", []):
        pbr = m.setdefault("pbrMetallicRoughness", {})
        if "baseColorTexture" in pbr:
            m["emissiveTexture"] = json.loads(json.dumps(pbr["baseColorTexture"]))
            m["emissiveFactor"] = [1.0, 1.0, 1.0]
            pbr["baseColorFactor"] = [0.0, 0.0, 0.0, 1.0]


def add_sun(direction, irradiance, environment):
    """An edit that adds a KHR_lights_punctual directional light of `irradiance` (lux) shining
    along `direction` (a node whose -Z is rotated onto it) and sets the scene's constant
    environment to `environment` (extras)."""
    d = np.array(direction, np.float64) / np.linalg.norm(direction)

    def edit(doc):
        # The rotation taking -Z to d: axis (-Z) x d, angle acos(-Z . d).
        axis = np.cross([0.0, 0.0, -1.0], d)
        s, c = np.linalg.norm(axis), -d[2]
        half = 0.5 * math.atan2(s, c)
        axis = axis / s if s > 1e-12 else np.array([1.0, 0.0, 0.0])
        q = [*(axis * math.sin(half)).tolist(), math.cos(half)]
        lights = doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {}).setdefault("lights", [])
        lights.append({"type": "directional", "intensity": irradiance})
        doc.setdefault("nodes", []).append({"name": "sun", "rotation": q,
                                            "extensions": {"KHR_lights_punctual": {"light": len(lights) - 1}}})
        scene = doc["scenes"][doc.get("scene", 0)]
        scene.setdefault("nodes", []).append(len(doc["nodes"]) - 1)
        scene.setdefault("extras", {})["environment"] = [environment] * 3
        used = doc.setdefault("extensionsUsed", [])
        if "KHR_lights_punctual" not in used:
            used.append("KHR_lights_punctual")
    return edit


def srgb_to_linear(c):
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4).astype(np.float32)


def node_matrix(node):
    if node.matrix:
        return np.array(node.matrix, np.float64).reshape(4, 4).T
    t = np.array(node.translation or [0, 0, 0], np.float64)
    x, y, z, w = node.rotation or [0, 0, 0, 1]
    s = np.array(node.scale or [1, 1, 1], np.float64)
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    m = np.eye(4)
    m[:3, :3] = r * s[None, :]
    m[:3, 3] = t
    return m


def scene_nodes(doc, scene_index):
    """(node, world matrix) for every node of the scene, depth first in scene order."""
    g = doc.g
    scene = g.scenes[scene_index if scene_index is not None else (g.scene or 0)]
    out = []

    def walk(i, parent):
        world = parent @ node_matrix(g.nodes[i])
        out.append((g.nodes[i], world))
        for c in g.nodes[i].children or []:
            walk(c, world)

    for i in scene.nodes or []:
        walk(i, np.eye(4))
    return out


def triangle_indices(doc, prim, vertex_count):
    mode = 4 if prim.mode is None else prim.mode
    idx = (doc.accessor(prim.indices)[:, 0].astype(np.int64) if prim.indices is not None
           else np.arange(vertex_count, dtype=np.int64))
    if mode == 4:
        return idx[: len(idx) // 3 * 3].reshape(-1, 3)
    if mode == 5:
        tris = [(idx[k], idx[k + 1], idx[k + 2]) if k % 2 == 0 else (idx[k + 1], idx[k], idx[k + 2])
                for k in range(len(idx) - 2)]
        return np.array(tris, np.int64).reshape(-1, 3)
    if mode == 6:
        return np.array([(idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1)], np.int64).reshape(-1, 3)
    return None


def texture_transform(info):
    """(texCoord set, 3x3 uv matrix) of a textureInfo: KHR_texture_transform's
    T(offset) R(rotation) S(scale) with u' = cos r u + sin r v, v' = -sin r u + cos r v: the sense
    that the Khronos TextureTransformTest sample marks correct (its arrows reach the green markers;
    the opposite sense reaches the red one)."""
    ext = (info.extensions or {}).get("KHR_texture_transform", {})
    u0, v0 = ext.get("offset", [0.0, 0.0])
    r = ext.get("rotation", 0.0)
    su, sv = ext.get("scale", [1.0, 1.0])
    c, s = math.cos(r), math.sin(r)
    t = np.array([[1, 0, u0], [0, 1, v0], [0, 0, 1]], np.float64)
    rot = np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]], np.float64)
    sc = np.diag([su, sv, 1.0])
    return ext.get("texCoord", info.texCoord or 0), t @ rot @ sc


class Materials:
    """glTF materials as Mitsuba BSDF and emitter dicts."""

    def __init__(self, doc, mi):
        self.doc, self.mi = doc, mi

    def bitmap(self, info, pixels):
        """A Mitsuba bitmap texture of float `pixels` (h, w, c), already linear and multiplied by
        its factor, sampled as the glTF texture `info` says."""
        mi, g = self.mi, self.doc.g
        tex = g.textures[info.index]
        sampler = g.samplers[tex.sampler] if tex.sampler is not None else None
        wrap_s = (sampler.wrapS if sampler and sampler.wrapS else GL_REPEAT)
        wrap_t = (sampler.wrapT if sampler and sampler.wrapT else GL_REPEAT)
        if wrap_s != wrap_t:
            warn("texture %d: wrapS %d and wrapT %d differ; Mitsuba has one wrap mode, wrapS is used"
                 % (info.index, wrap_s, wrap_t))
        nearest = sampler is not None and sampler.magFilter == GL_NEAREST
        _, m = texture_transform(info)
        return {
            "type": "bitmap", "bitmap": mi.Bitmap(np.ascontiguousarray(pixels, np.float32)), "raw": True,
            "filter_type": "nearest" if nearest else "bilinear",
            "wrap_mode": {GL_REPEAT: "repeat", GL_CLAMP: "clamp", GL_MIRROR: "mirror"}[wrap_s],
            "to_uv": mi.ScalarTransform3f(m.tolist()),
        }

    def image(self, info):
        return self.doc.image_rgba(self.doc.g.textures[info.index].source)

    def uv_set(self, m):
        """The texture coordinate set this material's textures use (Mitsuba meshes have one)."""
        pbr = m.pbrMetallicRoughness
        infos = [i for i in (pbr and pbr.baseColorTexture, pbr and pbr.metallicRoughnessTexture,
                             m.emissiveTexture, m.normalTexture) if i is not None]
        sets = sorted({texture_transform(i)[0] for i in infos})
        if len(sets) > 1:
            warn("material %r: textures use coordinate sets %s; set %d is used for all" % (m.name, sets, sets[0]))
        return sets[0] if sets else 0

    def bsdf(self, m):
        """The BSDF dict of glTF material `m` (None: the glTF default material)."""
        if m is None:
            return {"type": "principled", "base_color": {"type": "rgb", "value": [1, 1, 1]},
                    "metallic": 1.0, "roughness": 1.0}
        pbr = m.pbrMetallicRoughness
        ext = m.extensions or {}
        factor = np.array(pbr.baseColorFactor if pbr and pbr.baseColorFactor else [1, 1, 1, 1], np.float64)
        metallic = pbr.metallicFactor if pbr and pbr.metallicFactor is not None else 1.0
        roughness = pbr.roughnessFactor if pbr and pbr.roughnessFactor is not None else 1.0
        if pbr and pbr.baseColorTexture is not None:
            rgb = srgb_to_linear(self.image(pbr.baseColorTexture)[:, :, :3]) * factor[:3].astype(np.float32)
            base = self.bitmap(pbr.baseColorTexture, rgb)
        else:
            base = {"type": "rgb", "value": factor[:3].tolist()}
        mr_tex = pbr.metallicRoughnessTexture if pbr else None
        specular = ext.get("KHR_materials_specular", {})
        if specular.get("specularFactor", 1.0) == 0.0 and metallic == 0.0 and mr_tex is None \
                and "KHR_materials_transmission" not in ext:
            bsdf = {"type": "diffuse", "reflectance": base}
        else:
            bsdf = {"type": "principled", "base_color": base, "metallic": metallic, "roughness": roughness,
                    "eta": ext.get("KHR_materials_ior", {}).get("ior", 1.5)}
            if mr_tex is not None:
                texels = self.image(mr_tex)
                bsdf["metallic"] = self.bitmap(mr_tex, texels[:, :, 2:3] * metallic)
                bsdf["roughness"] = self.bitmap(mr_tex, texels[:, :, 1:2] * roughness)
            if specular:
                warn("material %r: KHR_materials_specular other than specularFactor 0 is not mapped "
                     "(Mitsuba's principled has no specular colour)" % m.name)
            trans = ext.get("KHR_materials_transmission")
            if trans:
                bsdf["spec_trans"] = trans.get("transmissionFactor", 0.0)
                if "transmissionTexture" in trans:
                    warn("material %r: transmissionTexture ignored (the factor is used)" % m.name)
        if m.normalTexture is not None:
            n = self.image(m.normalTexture)[:, :, :3] * 2.0 - 1.0
            scale = m.normalTexture.scale if m.normalTexture.scale is not None else 1.0
            n[:, :, :2] *= scale
            n /= np.maximum(np.linalg.norm(n, axis=2, keepdims=True), 1e-8)
            bsdf = {"type": "normalmap", "normalmap": self.bitmap(m.normalTexture, (n + 1.0) * 0.5), "bsdf": bsdf}
        if m.alphaMode not in (None, "OPAQUE"):
            warn("material %r: alphaMode %s rendered opaque" % (m.name, m.alphaMode))
        return bsdf

    def emission(self, m):
        """The area emitter dict of material `m`, or None."""
        if m is None:
            return None
        strength = (m.extensions or {}).get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
        e = np.array(m.emissiveFactor or [0, 0, 0], np.float64) * strength
        if "KHR_materials_unlit" in (m.extensions or {}):
            warn("material %r: KHR_materials_unlit is not mapped" % m.name)
        if e.max() <= 0.0:
            return None
        if m.emissiveTexture is not None:
            rgb = srgb_to_linear(self.image(m.emissiveTexture)[:, :, :3]) * e.astype(np.float32)
            return {"type": "area", "radiance": self.bitmap(m.emissiveTexture, rgb)}
        return {"type": "area", "radiance": {"type": "rgb", "value": e.tolist()}}


def build_meshes(doc, materials, nodes, mi):
    """Scene-dict entries of every triangle primitive, and the world bounds of their vertices."""
    g = doc.g
    entries, lo, hi = {}, np.full(3, np.inf), np.full(3, -np.inf)
    bsdfs, emitters = {}, {}
    for n_index, (node, world) in enumerate(nodes):
        if node.mesh is None:
            continue
        if node.extensions and "EXT_mesh_gpu_instancing" in node.extensions:
            warn("node %r: EXT_mesh_gpu_instancing is not expanded here" % node.name)
        normal_matrix = np.linalg.inv(world[:3, :3]).T
        mirrored = np.linalg.det(world[:3, :3]) < 0
        for p_index, prim in enumerate(g.meshes[node.mesh].primitives):
            attrs = prim.attributes
            pos = doc.accessor(attrs.POSITION)
            tris = triangle_indices(doc, prim, len(pos))
            if tris is None or len(tris) == 0:
                continue
            if mirrored:
                tris = tris[:, [0, 2, 1]]
            mat = g.materials[prim.material] if prim.material is not None else None
            uv_set = materials.uv_set(mat) if mat is not None else 0
            uv_acc = getattr(attrs, "TEXCOORD_%d" % uv_set, None)
            world_pos = pos @ world[:3, :3].T + world[:3, 3]
            lo, hi = np.minimum(lo, world_pos[tris.ravel()].min(0)), np.maximum(hi, world_pos[tris.ravel()].max(0))
            props = mi.Properties()
            if prim.material not in bsdfs:
                bsdfs[prim.material] = mi.load_dict(materials.bsdf(mat))
                em = materials.emission(mat)
                emitters[prim.material] = em
            props["bsdf"] = bsdfs[prim.material]
            if emitters[prim.material] is not None:
                props["emitter"] = mi.load_dict(emitters[prim.material])
            mesh = mi.Mesh("node%d_prim%d" % (n_index, p_index), len(pos), len(tris), props=props,
                           has_vertex_normals=attrs.NORMAL is not None, has_vertex_texcoords=uv_acc is not None)
            params = mi.traverse(mesh)
            params["vertex_positions"] = world_pos.astype(np.float32).ravel()
            if attrs.NORMAL is not None:
                nrm = doc.accessor(attrs.NORMAL) @ normal_matrix.T
                nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-12)
                params["vertex_normals"] = nrm.astype(np.float32).ravel()
            if uv_acc is not None:
                params["vertex_texcoords"] = doc.accessor(uv_acc).astype(np.float32).ravel()
            params["faces"] = tris.astype(np.uint32).ravel()
            params.update()
            entries["mesh_%d_%d" % (n_index, p_index)] = mesh
    if not entries:
        raise SystemExit("error: %s: the scene has no renderable triangles" % doc.path)
    return entries, (lo, hi)


def tan_half_fov(yfov, aspect_ratio, width, height):
    """restir-pt's Camera::tan_half_fov: an image narrower than the camera widens the view."""
    t = math.tan(0.5 * yfov)
    image_aspect = width / height
    return t * aspect_ratio / image_aspect if aspect_ratio and image_aspect < aspect_ratio else t


def sensor(doc, nodes, bounds, camera_index, args, mi):
    """The perspective sensor: the scene's camera `camera_index` (scene order), else restir-pt's
    default camera framing the bounds."""
    cams = [(n, w) for n, w in nodes if n.camera is not None
            and doc.g.cameras[n.camera].type == "perspective"]
    if camera_index < len(cams):
        node, world = cams[camera_index]
        persp = doc.g.cameras[node.camera].perspective
        eye = world[:3, 3]
        fwd = world[:3, :3] @ np.array([0, 0, -1.0])
        up = world[:3, :3] @ np.array([0, 1.0, 0])
        yfov, aspect = persp.yfov, persp.aspectRatio
    else:
        lo, hi = bounds
        centre, radius = 0.5 * (lo + hi), max(0.5 * np.linalg.norm(hi - lo), 1e-6)
        eye = centre + DEFAULT_VIEW * radius / math.sin(0.5 * DEFAULT_YFOV)
        fwd, up, yfov, aspect = centre - eye, np.array([0, 1.0, 0]), DEFAULT_YFOV, 1.0
    t = tan_half_fov(yfov, aspect, args.width, args.height)
    return {
        "type": "perspective", "fov_axis": "y", "fov": math.degrees(2 * math.atan(t)),
        "to_world": mi.ScalarTransform4f().look_at(origin=eye.tolist(), target=(eye + fwd).tolist(), up=up.tolist()),
        "film": {"type": "hdrfilm", "width": args.width, "height": args.height, "rfilter": {"type": "box"},
                 "pixel_format": "rgb"},
        "sampler": {"type": "independent", "sample_count": args.spp // args.passes},
    }


def punctual_lights(doc, nodes, mi):
    defs = ((doc.g.extensions or {}).get("KHR_lights_punctual") or {}).get("lights", [])
    out = {}
    for k, (node, world) in enumerate(nodes):
        ext = (node.extensions or {}).get("KHR_lights_punctual")
        if ext is None:
            continue
        light = defs[ext["light"]]
        value = (np.array(light.get("color", [1, 1, 1])) * light.get("intensity", 1.0)).tolist()
        pos = world[:3, 3]
        direction = world[:3, :3] @ np.array([0, 0, -1.0])
        direction /= np.linalg.norm(direction)
        kind = light["type"]
        if kind == "point":
            out["light%d" % k] = {"type": "point", "position": pos.tolist(), "intensity": {"type": "rgb", "value": value}}
        elif kind == "directional":
            out["light%d" % k] = {"type": "directional", "direction": direction.tolist(),
                                  "irradiance": {"type": "rgb", "value": value}}
        elif kind == "spot":
            spot = light.get("spot", {})
            warn("spot light %d: Mitsuba's falloff between the cone angles differs from the extension's" % k)
            up = [0, 1, 0] if abs(direction[1]) < 0.9 else [1, 0, 0]
            out["light%d" % k] = {
                "type": "spot", "intensity": {"type": "rgb", "value": value},
                "cutoff_angle": math.degrees(spot.get("outerConeAngle", math.pi / 4)),
                "beam_width": math.degrees(spot.get("innerConeAngle", 0.0)),
                "to_world": mi.ScalarTransform4f().look_at(origin=pos.tolist(), target=(pos + direction).tolist(), up=up)}
    return out


def environment(doc, scene_index):
    g = doc.g
    scene = g.scenes[scene_index if scene_index is not None else (g.scene or 0)]
    for extras in (scene.extras, g.extras):
        if isinstance(extras, dict) and "environment" in extras:
            return [float(c) for c in extras["environment"]]
    return [0.0, 0.0, 0.0]


def tile_means(img, tiles):
    """Mean RGB of each tile of a tiles x tiles grid, row-major from the top-left, (tiles^2, 3)."""
    h, w, _ = img.shape
    out = []
    for ty in range(tiles):
        for tx in range(tiles):
            block = img[ty * h // tiles:(ty + 1) * h // tiles, tx * w // tiles:(tx + 1) * w // tiles, :3]
            out.append(block.reshape(-1, 3).mean(0))
    return np.array(out)


def statistics(passes, tiles):
    """Means and standard errors over independent equal-spp passes, (h, w, 3) each."""
    p = len(passes)
    whole = np.array([img[:, :, :3].reshape(-1, 3).mean(0) for img in passes])
    grid = np.array([tile_means(img, tiles) for img in passes])
    se = (lambda a: (a.std(0, ddof=1) / math.sqrt(p)) if p > 1 else np.full(a.shape[1:], np.nan))
    return {
        "mean_rgb": whole.mean(0).tolist(), "mean_rgb_se": se(whole).tolist(),
        "tile_mean_rgb": grid.mean(0).tolist(), "tile_mean_rgb_se": se(grid).tolist(),
    }


def read_exr(path):
    import mitsuba as mi
    if not mi.variant():
        mi.set_variant("scalar_rgb")
    return np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False), np.float32)


def compare(exr, json_path):
    """Prints an EXR's tile means beside a reference JSON's, with the differences in standard errors."""
    ref = json.load(open(json_path))
    img = read_exr(exr)
    tiles = ref["settings"]["tiles"]
    ours, theirs = tile_means(img, tiles), np.array(ref["tile_mean_rgb"])
    se = np.array(ref["tile_mean_rgb_se"])
    print("mean RGB: this %s, reference %s, ratio %s" % (
        np.round(img[:, :, :3].reshape(-1, 3).mean(0), 4), np.round(ref["mean_rgb"], 4),
        np.round(img[:, :, :3].reshape(-1, 3).mean(0) / np.maximum(ref["mean_rgb"], 1e-9), 3)))
    for k in range(tiles * tiles):
        print("tile %2d: this %s reference %s ratio %s ref SE %s" % (
            k, np.round(ours[k], 4), np.round(theirs[k], 4), np.round(ours[k] / np.maximum(theirs[k], 1e-9), 3),
            np.round(se[k], 4)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("gltf", help="glTF 2.0 file (.gltf or .glb); with --compare, an EXR")
    ap.add_argument("--compare", metavar="JSON", help="print the tile means of the EXR given as gltf beside this JSON's")
    ap.add_argument("--variant", default="scalar_rgb")
    ap.add_argument("--width", type=int, default=64)
    ap.add_argument("--height", type=int, default=64)
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--passes", type=int, default=8, help="independent passes (for the standard errors)")
    ap.add_argument("--max-depth", type=int, default=7, help="path segments, as restir-pt's --max-depth")
    ap.add_argument("--camera", type=int, default=0)
    ap.add_argument("--scene", type=int, default=None)
    ap.add_argument("--tiles", type=int, default=4)
    ap.add_argument("--lambertian", action="store_true",
                    help="render every material as a Lambertian of its base colour (make_lambertian)")
    ap.add_argument("--emissive", action="store_true",
                    help="every base colour texture becomes the material's emission (make_emissive)")
    ap.add_argument("--sun", metavar="DX,DY,DZ,E,ENV",
                    help="add a directional light along (DX, DY, DZ) of irradiance E and a constant environment ENV")
    ap.add_argument("--out", help="EXR of the image (all passes)")
    ap.add_argument("--json", help="image statistics")
    args = ap.parse_args()
    if args.compare:
        compare(args.gltf, args.compare)
        return
    if args.spp % args.passes:
        raise SystemExit("error: --spp %d is not a multiple of --passes %d" % (args.spp, args.passes))
    import mitsuba as mi
    mi.set_variant(args.variant)
    edits = ([make_lambertian] if args.lambertian else []) + ([make_emissive] if args.emissive else []) + (
        [add_sun((lambda v: (v[:3], v[3], v[4]))([float(x) for x in args.sun.split(",")])[0],
                 *[float(x) for x in args.sun.split(",")][3:5])] if args.sun else [])
    doc = Gltf(args.gltf, edits)
    nodes = scene_nodes(doc, args.scene)
    scene = {"type": "scene", "integrator": {"type": "path", "max_depth": args.max_depth}}
    meshes, bounds = build_meshes(doc, Materials(doc, mi), nodes, mi)
    scene.update(meshes)
    scene["sensor"] = sensor(doc, nodes, bounds, args.camera, args, mi)
    lights = punctual_lights(doc, nodes, mi)
    scene.update(lights)
    env = environment(doc, args.scene)
    has_emitter = any(m.emitter() is not None for m in meshes.values())
    if max(env) <= 0 and not lights and not has_emitter:
        env = [1.0, 1.0, 1.0]
        warn("no light in the file: a uniform environment of radiance 1, as restir-pt uses")
    if max(env) > 0:
        scene["environment"] = {"type": "constant", "radiance": {"type": "rgb", "value": env}}
    loaded = mi.load_dict(scene)
    t0 = time.perf_counter()
    passes = [np.array(mi.render(loaded, seed=k), np.float32) for k in range(args.passes)]
    seconds = time.perf_counter() - t0
    image = np.mean(passes, axis=0)
    if not np.isfinite(image).all():
        raise SystemExit("error: %s: Mitsuba's image has non-finite pixels" % args.gltf)
    if args.out:
        os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
        mi.Bitmap(image).write(args.out)
    stats = {
        "source": os.path.relpath(os.path.abspath(args.gltf)),
        "renderer": "mitsuba %s %s, path integrator" % (mi.__version__, args.variant),
        "settings": {"width": args.width, "height": args.height, "spp": args.spp, "passes": args.passes,
                     "max_depth": args.max_depth, "camera": args.camera, "tiles": args.tiles,
                     "environment": env, "lambertian": args.lambertian, "emissive": args.emissive, "sun": args.sun},
        "command": "python3 tools/mitsuba_reference.py " + " ".join(sys.argv[1:]),
        "render_seconds": round(seconds, 1),
    }
    stats.update(statistics(passes, args.tiles))
    text = json.dumps(stats, indent=1)
    if args.json:
        os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
        with open(args.json, "w") as f:
            f.write(text + "\n")
    print("mean RGB %s (SE %s), %.1f s" % (np.round(stats["mean_rgb"], 4), np.round(stats["mean_rgb_se"], 5), seconds))


if __name__ == "__main__":
    main()
