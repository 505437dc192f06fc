#!/usr/bin/python3
"""make_hard_scenes.py — writes the small glTF scenes of scenes/hard/ (issue #4, hard cases).

Pure Python 3 standard library; deterministic (same bytes on every run). Each scene is one
.gltf file with its buffer embedded as a base64 data URI, so a scene is a single file.

    /usr/bin/python3 tools/make_hard_scenes.py [output folder, default scenes/hard]

Scenes:
  icosphere-smooth.gltf   level-1 icosphere (80 triangles, shared vertices, smooth normals = the
                          unit sphere's normals, so shading and geometric normals disagree by up
                          to ~18 degrees), a directional light from +y+z, a camera on +z.
  icosphere-closed.gltf   level-3 icosphere (1280 triangles, closed, shared vertices) for the
                          watertightness test.
  light-in-box.gltf       a closed box (12 triangles, shared vertices, outward normals) with an
                          emissive quad inside facing down, standing on a floor; camera outside.
  tilted-normals.gltf     a quad at y = 0 facing +y whose vertex normals are tilted 60 degrees
                          towards +x, and a point light BELOW it; camera above.
"""
import base64
import json
import math
import os
import struct
import sys


def icosphere(level):
    t = (1.0 + math.sqrt(5.0)) / 2.0
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
             (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [normalize(v) for v in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
             (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(level):
        cache = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                va, vb = verts[a], verts[b]
                verts.append(normalize(((va[0] + vb[0]) / 2, (va[1] + vb[1]) / 2, (va[2] + vb[2]) / 2)))
                cache[key] = len(verts) - 1
            return cache[key]

        new_faces = []
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            new_faces += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new_faces
    return verts, faces


def normalize(v):
    n = math.sqrt(sum(x * x for x in v))
    return tuple(x / n for x in v)


class Gltf:
    def __init__(self):
        self.data = bytearray()
        self.doc = {"asset": {"version": "2.0", "generator": "tools/make_hard_scenes.py"},
                    "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [], "materials": [],
                    "accessors": [], "bufferViews": [], "buffers": []}

    def _view(self, payload, target):
        while len(self.data) % 4:
            self.data.append(0)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": len(self.data), "byteLength": len(payload),
                                        "target": target})
        self.data += payload
        return len(self.doc["bufferViews"]) - 1

    def _accessor(self, values, kind):
        if kind == "VEC3":
            payload = b"".join(struct.pack("<3f", *v) for v in values)
            f32 = [struct.unpack("<3f", struct.pack("<3f", *v)) for v in values]
            acc = {"componentType": 5126, "type": "VEC3", "count": len(values),
                   "min": [min(v[i] for v in f32) for i in range(3)], "max": [max(v[i] for v in f32) for i in range(3)]}
            target = 34962
        else:
            payload = b"".join(struct.pack("<I", i) for i in values)
            acc = {"componentType": 5125, "type": "SCALAR", "count": len(values)}
            target = 34963
        acc["bufferView"] = self._view(payload, target)
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def material(self, name, color, emission=None, strength=1.0, double_sided=False):
        m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": list(color) + [1.0], "metallicFactor": 0.0,
                                                    "roughnessFactor": 1.0}, "doubleSided": double_sided}
        if emission:
            m["emissiveFactor"] = list(emission)
            if strength != 1.0:
                m["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": strength}}
                self.doc.setdefault("extensionsUsed", []).append("KHR_materials_emissive_strength")
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def mesh(self, name, positions, triangles, material, normals=None):
        attributes = {"POSITION": self._accessor(positions, "VEC3")}
        if normals is not None:
            attributes["NORMAL"] = self._accessor(normals, "VEC3")
        indices = self._accessor([i for t in triangles for i in t], "SCALAR")
        self.doc["meshes"].append({"name": name, "primitives": [
            {"attributes": attributes, "indices": indices, "material": material, "mode": 4}]})
        self.node({"name": name, "mesh": len(self.doc["meshes"]) - 1})

    def node(self, node):
        self.doc["nodes"].append(node)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def camera(self, position, yfov, rotation=(0.0, 0.0, 0.0, 1.0)):
        self.doc.setdefault("cameras", []).append(
            {"type": "perspective", "perspective": {"yfov": yfov, "aspectRatio": 1.0, "znear": 0.01}})
        self.node({"name": "camera", "camera": len(self.doc["cameras"]) - 1, "translation": list(position),
                   "rotation": list(rotation)})

    def light(self, light, translation=None, rotation=None):
        ext = self.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {"lights": []})
        ext["lights"].append(light)
        if "KHR_lights_punctual" not in self.doc.setdefault("extensionsUsed", []):
            self.doc["extensionsUsed"].append("KHR_lights_punctual")
        node = {"name": light["name"], "extensions": {"KHR_lights_punctual": {"light": len(ext["lights"]) - 1}}}
        if translation:
            node["translation"] = list(translation)
        if rotation:
            node["rotation"] = list(rotation)
        self.node(node)

    def write(self, path):
        self.doc["buffers"] = [{"byteLength": len(self.data),
                                "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(self.data)).decode()}]
        if not self.doc["accessors"]:
            del self.doc["buffers"], self.doc["bufferViews"], self.doc["accessors"]
        with open(path, "w") as f:
            json.dump(self.doc, f, indent=1)
            f.write("\n")


def quat_x(angle):  # rotation about +x
    return (math.sin(angle / 2), 0.0, 0.0, math.cos(angle / 2))


def icosphere_scene(path, level, with_light):
    g = Gltf()
    m = g.material("sphere", (0.8, 0.8, 0.8))
    verts, faces = icosphere(level)
    g.mesh("icosphere", verts, faces, m, normals=verts if with_light else None)
    if with_light:
        # glTF lights shine along their node's -z: rotate -z to (0, -1, -1)/sqrt(2), a sun from +y+z.
        g.light({"name": "sun", "type": "directional", "intensity": 1.0, "color": [1.0, 1.0, 1.0]},
                rotation=quat_x(-math.pi / 4))
    g.camera((0.0, 0.0, 4.0), 0.6)
    g.write(path)


def box(lo, hi):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    p = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0), (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    # Counter-clockwise seen from outside: outward normals.
    t = [(0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4), (3, 7, 6), (3, 6, 2), (0, 4, 7), (0, 7, 3),
         (1, 2, 6), (1, 6, 5)]
    return p, t


def light_in_box(path):
    g = Gltf()
    wall = g.material("box", (0.7, 0.7, 0.7))
    floor = g.material("floor", (0.5, 0.5, 0.5))
    light = g.material("inner_light", (0.0, 0.0, 0.0), emission=(1.0, 1.0, 1.0), strength=10.0)
    p, t = box((-0.5, 0.0, -0.5), (0.5, 1.0, 0.5))
    g.mesh("closed_box", p, t, wall)
    g.mesh("floor", [(-3.0, 0.0, -3.0), (3.0, 0.0, -3.0), (3.0, 0.0, 3.0), (-3.0, 0.0, 3.0)], [(0, 2, 1), (0, 3, 2)], floor)
    # Inside the box, 0.1 under its lid, facing down (-y).
    g.mesh("inner_light", [(-0.2, 0.9, -0.2), (0.2, 0.9, -0.2), (0.2, 0.9, 0.2), (-0.2, 0.9, 0.2)], [(0, 1, 2), (0, 2, 3)], light)
    g.camera((0.0, 2.0, 4.0), 0.8, rotation=quat_x(-0.45))
    g.write(path)


def tilted_normals(path):
    g = Gltf()
    m = g.material("plane", (0.8, 0.8, 0.8))
    n = (math.sin(math.radians(60)), math.cos(math.radians(60)), 0.0)  # 60 degrees from +y towards +x
    g.mesh("tilted_quad", [(-1.0, 0.0, -1.0), (1.0, 0.0, -1.0), (1.0, 0.0, 1.0), (-1.0, 0.0, 1.0)],
           [(0, 2, 1), (0, 3, 2)], m, normals=[n] * 4)
    # A point light below the plane, on the side the shading normals lean towards.
    g.light({"name": "below", "type": "point", "intensity": 10.0, "color": [1.0, 1.0, 1.0]}, translation=(1.5, -0.3, 0.0))
    g.camera((0.0, 2.0, 0.0), 1.2, rotation=quat_x(-math.pi / 2))
    g.write(path)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "scenes", "hard")
    os.makedirs(out, exist_ok=True)
    icosphere_scene(os.path.join(out, "icosphere-smooth.gltf"), 1, True)
    icosphere_scene(os.path.join(out, "icosphere-closed.gltf"), 3, False)
    light_in_box(os.path.join(out, "light-in-box.gltf"))
    tilted_normals(os.path.join(out, "tilted-normals.gltf"))


if __name__ == "__main__":
    main()
