"""glTF 2.0 files read with pygltflib and numpy for tools/mitsuba_reference.py: accessors (strided,
normalised, sparse), images, the node tree, triangle primitives, texture transforms, and the edits
that the reference script and tests/suite/independent_renderer.rs both make to a file
(`make_lambertian`, `make_emissive`, `add_sun`; the test has Rust twins of the same names)."""
import json
import math
import os
import sys

import numpy as np


GL_REPEAT, GL_CLAMP, GL_MIRROR = 10497, 33071, 33648
GL_NEAREST = 9728
COMPONENT = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


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
