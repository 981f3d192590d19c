#!/usr/bin/env python3
"""Writes the regression inputs of tests/loader_hardening_test.cpp (issue 27) into this directory.

Each file is the smallest input that reproduced one finding: a crash, a hang, an
out-of-bounds access or an uncaught exception in chorus's loaders. docs/hardening-inputs.md lists them with
the finding and the expected error. Run from anywhere: python3 make_inputs.py

With --memory-scenes DIR it instead writes the two large scenes that docs/hardening-inputs.md
measures the memory per triangle and per vertex with (not committed: 36 and 72 MB).
"""
import base64
import json
import os
import struct
import sys
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def write(name, data):
    mode = "wb" if isinstance(data, (bytes, bytearray)) else "w"
    with open(os.path.join(HERE, name), mode) as f:
        f.write(data)


def data_uri(data):
    return "data:application/octet-stream;base64," + base64.b64encode(data).decode()


def triangle(positions=((0, 0, 0), (1, 0, 0), (0, 1, 0))):
    """One triangle in node 0 of scene 0; its positions are accessor 0 over bufferView 0."""
    data = b"".join(struct.pack("<3f", *p) for p in positions)
    return {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "buffers": [{"byteLength": len(data), "uri": data_uri(data)}],
        "bufferViews": [{"buffer": 0, "byteLength": len(data)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(positions),
                       "type": "VEC3"}],
    }


def gltf(name, g):
    write(name, json.dumps(g, indent=1) + "\n")


def with_camera(g, camera, translation=(0, 0, 5)):
    g["nodes"].append({"camera": 0, "translation": list(translation)})
    g["scenes"][0]["nodes"].append(len(g["nodes"]) - 1)
    g["cameras"] = [camera]
    return g


def with_light(g, light, translation):
    g["extensionsUsed"] = ["KHR_lights_punctual"]
    g["extensions"] = {"KHR_lights_punctual": {"lights": [light]}}
    g["nodes"].append({"translation": list(translation),
                       "extensions": {"KHR_lights_punctual": {"light": 0}}})
    g["scenes"][0]["nodes"].append(len(g["nodes"]) - 1)
    return g


def memory_scenes(out_dir):
    """A 1000 x 1000 quad grid (2M triangles over 1M shared vertices) and the same triangles
    as a soup (6M vertices): their peak memory difference separates triangles from vertices."""
    n = 1000
    grid = [struct.pack("<3f", i / n, j / n, 0) for j in range(n + 1) for i in range(n + 1)]
    indices = []
    soup = []
    for j in range(n):
        for i in range(n):
            a, b, c, d = j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i, (j + 1) * (n + 1) + i + 1
            indices += [a, b, d, a, d, c]
            soup += [grid[k] for k in (a, b, d, a, d, c)]
    for name, positions, idx in [("grid", grid, indices), ("soup", soup, None)]:
        pos = b"".join(positions)
        data = pos + (struct.pack("<%dI" % len(idx), *idx) if idx else b"")
        with open(os.path.join(out_dir, name + ".bin"), "wb") as f:
            f.write(data)
        g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
             "nodes": [{"mesh": 0}],
             "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
             "buffers": [{"byteLength": len(data), "uri": name + ".bin"}],
             "bufferViews": [{"buffer": 0, "byteLength": len(pos)}],
             "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(positions),
                            "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}]}
        if idx:
            g["meshes"][0]["primitives"][0]["indices"] = 1
            g["bufferViews"].append({"buffer": 0, "byteOffset": len(pos), "byteLength": 4 * len(idx)})
            g["accessors"].append({"bufferView": 1, "componentType": 5125, "count": len(idx),
                                   "type": "SCALAR"})
        with open(os.path.join(out_dir, name + ".gltf"), "w") as f:
            json.dump(g, f)


if len(sys.argv) == 3 and sys.argv[1] == "--memory-scenes":
    memory_scenes(sys.argv[2])
    sys.exit(0)


# Accessor counts whose products wrapped (heap overflow write) or exhausted memory.
for name, count in [("accessor-count-wraps", (2**64 + 2) // 3), ("accessor-count-2e63", 2**63),
                    ("accessor-count-2e62", 2**62), ("accessor-count-2e32", 2**32)]:
    g = triangle()
    g["accessors"][0]["count"] = count
    gltf(name + ".gltf", g)

# byteOffset near 2^64: byteOffset + stride · (count − 1) + elementBytes wrapped to a small value.
g = triangle()
g["accessors"][0]["byteOffset"] = 2**64 - 4
gltf("accessor-offset-wraps.gltf", g)

# Sparse accessors: more sparse values than elements; signed byte sparse indices (read as 4 bytes).
g = triangle()
idx = struct.pack("<3B", 0, 1, 2) + b"\0"
vals = struct.pack("<9f", *([5.0] * 9))
both = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + idx + vals
g["buffers"][0] = {"byteLength": len(both), "uri": data_uri(both)}
g["bufferViews"] = [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 4},
                    {"buffer": 0, "byteOffset": 40, "byteLength": 36}]
g["accessors"][0]["sparse"] = {"count": 7, "indices": {"bufferView": 1, "componentType": 5121},
                               "values": {"bufferView": 2}}
gltf("sparse-count-exceeds-count.gltf", g)
g["accessors"][0]["sparse"] = {"count": 1, "indices": {"bufferView": 1, "componentType": 5120},
                               "values": {"bufferView": 2}}
gltf("sparse-signed-indices.gltf", g)

# An image stored in a buffer view that lies outside its buffer (tinygltf read past the buffer).
g = triangle()
g["images"] = [{"bufferView": 1, "mimeType": "image/png"}]
g["bufferViews"].append({"buffer": 0, "byteOffset": 30, "byteLength": 1000000})
g["textures"] = [{"source": 0}]
g["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
g["meshes"][0]["primitives"][0]["material"] = 0
gltf("image-view-outside-buffer.gltf", g)

# 100 000 nested arrays in extras: stack overflow in the JSON handling (also as GLB).
text = json.dumps(triangle())
deep = text[:-1] + ', "extras": ' + "[" * 100000 + "]" * 100000 + "}"
write("deep-extras.gltf", deep)
chunk = deep.encode()
chunk += b" " * (-len(chunk) % 4)
write("deep-extras.glb", b"glTF" + struct.pack("<II", 2, 20 + len(chunk)) +
      struct.pack("<I", len(chunk)) + b"JSON" + chunk)

# A node DAG: each of 24 levels lists the next node twice (2^24 instances of one triangle).
g = triangle()
g["nodes"] = [{"children": [i + 1, i + 1]} for i in range(24)] + [{"mesh": 0}]
gltf("node-dag-24-levels.gltf", g)

# Coordinates and camera parameters beyond Embree's valid ray range (its assertion aborted).
gltf("vertex-at-1e20.gltf", triangle([(1e20, 0, 0), (1e20 + 1e5, 0, 0), (1e20, 1e5, 0)]))
gltf("node-scale-1e20.gltf", dict(triangle(), nodes=[{"mesh": 0, "scale": [1e20, 1e20, 1e20]}]))
gltf("camera-at-1e20.gltf", with_camera(triangle(), {"type": "perspective",
     "perspective": {"yfov": 0.8, "znear": 0.1}}, (0, 0, 1e20)))
gltf("orthographic-ymag-1e20.gltf", with_camera(triangle(), {"type": "orthographic",
     "orthographic": {"xmag": 1, "ymag": 1e20, "znear": 0.1, "zfar": 100}}))
gltf("orthographic-xmag-1e-30.gltf", with_camera(triangle(), {"type": "orthographic",
     "orthographic": {"xmag": 1e-30, "ymag": 1, "znear": 0.1, "zfar": 100}}))
gltf("perspective-aspect-1e30.gltf", with_camera(triangle(), {"type": "perspective",
     "perspective": {"yfov": 0.8, "aspectRatio": 1e30, "znear": 0.1}}))
gltf("light-at-1e20.gltf", with_light(triangle(), {"type": "point", "intensity": 10},
                                      (0, 1e20, 0)))
# Radiances that became +inf as floats (and NaN in the image).
gltf("light-intensity-1e300.gltf", with_light(triangle(), {"type": "point", "intensity": 1e300},
                                              (0, 0, 2)))
g = triangle()
g["extensionsUsed"] = ["KHR_materials_emissive_strength"]
g["materials"] = [{"emissiveFactor": [1, 1, 1],
                   "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 1e300}}}]
g["meshes"][0]["primitives"][0]["material"] = 0
gltf("emissive-strength-1e300.gltf", g)

# A texture whose PNG header claims 20000 x 20000 pixels (1.6 GB of RGBA, within stb's own limit).
def png_chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


png = (b"\x89PNG\r\n\x1a\n" + png_chunk(b"IHDR", struct.pack(">IIBBBBB", 20000, 20000, 8, 6, 0, 0, 0)) +
       png_chunk(b"IDAT", zlib.compress(b"\0" * 64)) + png_chunk(b"IEND", b""))
g = triangle()
g["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(png).decode()}]
g["textures"] = [{"source": 0}]
g["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
g["meshes"][0]["primitives"][0]["material"] = 0
gltf("texture-claims-20000x20000.gltf", g)

# A buffer uri naming a directory (bad_alloc: "internal error", exit 1).
g = triangle()
g["buffers"][0]["uri"] = "."
gltf("buffer-uri-directory.gltf", g)


# Radiance HDR files: RGBE pixels, header, then flat or run-length scanlines.
def hdr_header(width, height):
    return b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (height, width)


def rle_row(pixels):
    """New-style run-length scanline: marker, then each component as literal runs of <= 128."""
    width = len(pixels)
    out = bytes([2, 2, width >> 8, width & 255])
    for c in range(4):
        comp = [p[c] for p in pixels]
        for start in range(0, width, 128):
            part = comp[start:start + 128]
            out += bytes([len(part)]) + bytes(part)
    return out


width, height = 16, 3
rows = [[((x * 16) % 256, (y * 80) % 256, 200 - x, 120 + y) for x in range(width)]
        for y in range(height)]
valid = hdr_header(width, height) + b"".join(rle_row(r) for r in rows)
write("env-valid-rle.hdr", valid)
# Truncated inside the second scanline: stb loops forever (CVE-2021-42715).
row_bytes = len(rle_row(rows[0]))
write("env-truncated-rle.hdr", valid[:len(hdr_header(width, height)) + row_bytes + 30])
# A run of length 0 (count byte 0, or 128 for a run): stb loops forever on it too.
zero = bytearray(valid)
zero[len(hdr_header(width, height)) + 4] = 0
write("env-zero-length-run.hdr", bytes(zero))
# Width 4 is stored flat; the pixel (128, 64, 32, 129) is (1, 0.5, 0.25).
write("env-valid-flat.hdr", hdr_header(4, 1) + bytes([128, 64, 32, 129]) * 4)


# OpenEXR: a minimal uncompressed scanline file, then headers claiming absurd data windows.
def attribute(name, type_name, value):
    return name.encode() + b"\0" + type_name.encode() + b"\0" + struct.pack("<i", len(value)) + value


def exr(window, channel_names=(b"B", b"G", b"R"), compression=0, lines_per_block=1,
        pixel_data=True):
    """Pixels 0.5 when pixel_data; otherwise only the header and a zeroed offset table."""
    width, height = window[2] - window[0] + 1, window[3] - window[1] + 1
    channels = b"".join(c + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in channel_names)
    header = (attribute("channels", "chlist", channels + b"\0") +
              attribute("compression", "compression", bytes([compression])) +
              attribute("dataWindow", "box2i", struct.pack("<4i", *window)) +
              attribute("displayWindow", "box2i", struct.pack("<4i", 0, 0, 1, 1)) +
              attribute("lineOrder", "lineOrder", b"\0") +
              attribute("pixelAspectRatio", "float", struct.pack("<f", 1)) +
              attribute("screenWindowCenter", "v2f", struct.pack("<2f", 0, 0)) +
              attribute("screenWindowWidth", "float", struct.pack("<f", 1)) + b"\0")
    blocks = (height + lines_per_block - 1) // lines_per_block
    if not pixel_data:
        return b"\x76\x2f\x31\x01" + struct.pack("<i", 2) + header + bytes(8 * blocks)
    start = 8 + len(header) + 8 * height
    lines = b""
    offsets = b""
    for y in range(height):
        line = struct.pack("<%df" % (len(channel_names) * width), *([0.5] * (len(channel_names) * width)))
        offsets += struct.pack("<Q", start + len(lines))
        lines += struct.pack("<ii", y, len(line)) + line
    return b"\x76\x2f\x31\x01" + struct.pack("<i", 2) + header + offsets + lines


write("exr-valid-2x2.exr", exr((0, 0, 1, 1)))
# Headers claiming more than chorus reads; ZIP (16 lines a block) keeps the offset tables small.
# 2^29 RGB pixels; 2^28 pixels of 9 channels (2.4e9 values: 9.7 GB of floats were allocated).
write("exr-32768x16384-pixels.exr", exr((0, 0, 32767, 16383), compression=3, lines_per_block=16,
                                        pixel_data=False))
write("exr-16384x16384x9-channels.exr",
      exr((0, 0, 16383, 16383), [b"c%d" % i for i in range(9)], compression=3,
          lines_per_block=16, pixel_data=False))
# A data window spanning all of int: its width 2^32 overflowed int.
write("exr-data-window-full-int.exr", exr((-2**31, -2**31, 2**31 - 1, 2**31 - 1), pixel_data=False,
                                          lines_per_block=2**30))
