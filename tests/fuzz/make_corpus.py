#!/usr/bin/env python3
"""Writes the seed corpus of the glTF loader fuzzer into tests/fuzz/corpus/ (run it again after
changing a seed; the files are checked in). The .gltf seeds refer to buffer.bin, tex.png and
tex.jpg, which the fuzzer (gltf_loader_fuzzer.cc) writes next to every input; quad_bin() here
must stay byte-identical to quadBin() there. The .glb seeds are self-contained."""
import base64
import json
import os
import struct
import sys
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "corpus")

FLOAT, USHORT, UINT, UBYTE = 5126, 5123, 5125, 5121


def quad_bin():
    b = b""
    for p in [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]:
        b += struct.pack("<3f", *p)
    for _ in range(4):
        b += struct.pack("<3f", 0, 0, 1)
    for uv in [(0, 0), (1, 0), (1, 1), (0, 1)]:
        b += struct.pack("<2f", *uv)
    b += struct.pack("<6H", 0, 1, 2, 0, 2, 3) + b"\0" * 4
    b += struct.pack("<6I", 0, 1, 2, 0, 2, 3)
    assert len(b) == 168
    return b


def tiny_png():
    """A 2x2 RGBA PNG, encoded here (filter 0 on every row)."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    rows = b"".join(b"\0" + bytes([255, 0, 0, 255, 0, 255, 0, 255]) for _ in range(2))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def quad_doc(uri="buffer.bin", index_type=USHORT, normals=True, uvs=True):
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
             {"buffer": 0, "byteOffset": 48, "byteLength": 48},
             {"buffer": 0, "byteOffset": 96, "byteLength": 32},
             {"buffer": 0, "byteOffset": 128, "byteLength": 12},
             {"buffer": 0, "byteOffset": 144, "byteLength": 24}]
    accessors = [{"bufferView": 0, "componentType": FLOAT, "count": 4, "type": "VEC3",
                  "min": [0, 0, 0], "max": [1, 1, 0]},
                 {"bufferView": 1, "componentType": FLOAT, "count": 4, "type": "VEC3"},
                 {"bufferView": 2, "componentType": FLOAT, "count": 4, "type": "VEC2"},
                 {"bufferView": 3 if index_type == USHORT else 4, "componentType": index_type, "count": 6,
                  "type": "SCALAR"}]
    attributes = {"POSITION": 0}
    if normals:
        attributes["NORMAL"] = 1
    if uvs:
        attributes["TEXCOORD_0"] = 2
    return {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": 3, "material": 0, "mode": 4}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0],
                                                "metallicFactor": 0.0, "roughnessFactor": 0.5}}],
        "buffers": [{"uri": uri, "byteLength": 168}],
        "bufferViews": views,
        "accessors": accessors,
    }


def seeds():
    out = {}
    d = quad_doc()
    out["quad.gltf"] = d

    d = quad_doc(index_type=UINT, normals=False)
    d["nodes"] = [{"children": [1, 2], "translation": [0, 0, -3], "rotation": [0, 0.7071068, 0, 0.7071068],
                   "scale": [1, 2, 1]},
                  {"mesh": 0, "matrix": [-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]},
                  {"camera": 0, "translation": [0, 0, 5]}]
    d["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.6, "aspectRatio": 1.5, "znear": 0.1}}]
    out["hierarchy_camera.gltf"] = d

    d = quad_doc()
    d["images"] = [{"uri": "tex.png"}, {"uri": "tex.jpg"}]
    d["textures"] = [{"source": 0}, {"source": 1}]
    d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    d["materials"][0]["pbrMetallicRoughness"]["metallicRoughnessTexture"] = {"index": 1}
    d["materials"][0]["emissiveTexture"] = {"index": 0}
    d["materials"][0]["emissiveFactor"] = [1, 0.5, 0.25]
    d["materials"][0]["alphaMode"] = "MASK"
    d["materials"][0]["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}
    d["extensionsUsed"] = ["KHR_materials_emissive_strength"]
    out["textured_emissive.gltf"] = d

    d = quad_doc()
    d["extensionsUsed"] = ["KHR_lights_punctual"]
    d["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"type": "point", "color": [1, 1, 1], "intensity": 10},
        {"type": "spot", "intensity": 5, "spot": {"innerConeAngle": 0.1, "outerConeAngle": 0.5}},
        {"type": "directional", "intensity": 2}]}}
    d["nodes"] = [{"mesh": 0, "children": [1, 2, 3]},
                  {"translation": [0, 2, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
                  {"rotation": [0.3826834, 0, 0, 0.9238795], "extensions": {"KHR_lights_punctual": {"light": 1}}},
                  {"extensions": {"KHR_lights_punctual": {"light": 2}}}]
    d["scenes"][0]["nodes"] = [0]
    out["lights.gltf"] = d

    d = quad_doc(uri="data:application/octet-stream;base64," + base64.b64encode(quad_bin()).decode())
    out["data_uri.gltf"] = d

    # Malformed ones, near the checks.
    d = quad_doc()
    d["accessors"][0]["count"] = 5
    out["accessor_past_view.gltf"] = d
    d = quad_doc()
    d["meshes"][0]["primitives"][0]["mode"] = 5
    out["strip_mode.gltf"] = d
    d = quad_doc()
    d["accessors"][3]["sparse"] = {"count": 1, "indices": {"bufferView": 3, "componentType": USHORT},
                                   "values": {"bufferView": 3}}
    out["sparse.gltf"] = d
    d = quad_doc()
    d["bufferViews"][1]["byteStride"] = 4
    out["bad_stride.gltf"] = d

    files = {name: json.dumps(doc, separators=(",", ":")).encode() for name, doc in out.items()}
    files["truncated.gltf"] = files["quad.gltf"][: len(files["quad.gltf"]) // 2]

    # GLB: JSON chunk + BIN chunk (quad + embedded PNG image).
    png = tiny_png()
    bin_data = quad_bin() + png
    bin_data += b"\0" * (-len(bin_data) % 4)
    d = quad_doc(uri=None)
    del d["buffers"][0]["uri"]
    d["buffers"][0]["byteLength"] = len(bin_data)
    d["bufferViews"].append({"buffer": 0, "byteOffset": 168, "byteLength": len(png)})
    d["images"] = [{"bufferView": 5, "mimeType": "image/png"}]
    d["textures"] = [{"source": 0}]
    d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    files["embedded_texture.glb"] = glb(d, bin_data)

    d = {"asset": {"version": "2.0"}, "scenes": [{"nodes": []}]}
    files["no_bin_chunk.glb"] = glb(d, None)
    return files


def glb(doc, bin_data):
    j = json.dumps(doc, separators=(",", ":")).encode()
    j += b" " * (-len(j) % 4)
    body = struct.pack("<II", len(j), 0x4E4F534A) + j
    if bin_data is not None:
        body += struct.pack("<II", len(bin_data), 0x004E4942) + bin_data
    return b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body


def main():
    os.makedirs(OUT, exist_ok=True)
    for name, data in seeds().items():
        with open(os.path.join(OUT, name), "wb") as f:
            f.write(data)
    print(f"wrote {len(seeds())} seeds to {OUT}", file=sys.stderr)


if __name__ == "__main__":
    main()
