#!/usr/bin/env python3
"""Writes chorus's own glTF 2.0 scenes (Python 3 standard library only).

    python3 scenes/generate_scenes.py [OUTPUT_DIR]     # default: the folder of this script

A development tool: the committed .gltf/.bin/.png files are what chorus uses; this script keeps
their geometry reproducible and reviewable. Scenes (see scenes/README.md):
  cornell-box.gltf       the default scene: the classic Cornell room, one emissive quad light
  glass-and-metal.gltf   glass sphere (transmission + volume), smooth and rough metal spheres,
                         checker floor (embedded PNG), one small bright emissive light
  punctual-lights.gltf   spot + point light (KHR_lights_punctual), brick floor with a normal map
  stiff-caustics.gltf    a tiny, very bright emitter inside a glass ball and a solid glass sphere
                         under a dim area light: light reaches the room through glass only, by
                         rare caustic paths (fireflies thousands of times the mean)
"""
import base64
import json
import math
import os
import struct
import sys
import zlib

FLOAT, UNSIGNED_SHORT = 5126, 5123
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
REPEAT, LINEAR, LINEAR_MIPMAP_LINEAR = 10497, 9729, 9987


# ---------------------------------------------------------------------------------------------
# Small vector helpers


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def add(a, b):
    return [a[i] + b[i] for i in range(3)]


def scale(a, s):
    return [x * s for x in a]


def dot(a, b):
    return sum(a[i] * b[i] for i in range(3))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def normalize(a):
    length = math.sqrt(dot(a, a))
    return [x / length for x in a]


def quat_from_matrix(m):
    """Unit quaternion [x, y, z, w] of a rotation matrix given as three column vectors."""
    (m00, m10, m20), (m01, m11, m21), (m02, m12, m22) = m
    trace = m00 + m11 + m22
    if trace > 0:
        s = 0.5 / math.sqrt(trace + 1.0)
        q = [(m21 - m12) * s, (m02 - m20) * s, (m10 - m01) * s, 0.25 / s]
    elif m00 > m11 and m00 > m22:
        s = 2.0 * math.sqrt(1.0 + m00 - m11 - m22)
        q = [0.25 * s, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s]
    elif m11 > m22:
        s = 2.0 * math.sqrt(1.0 + m11 - m00 - m22)
        q = [(m01 + m10) / s, 0.25 * s, (m12 + m21) / s, (m02 - m20) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + m22 - m00 - m11)
        q = [(m02 + m20) / s, (m12 + m21) / s, 0.25 * s, (m10 - m01) / s]
    return [round(v, 7) for v in q]


def look_at_rotation(eye, target, up=(0.0, 1.0, 0.0)):
    """Rotation taking glTF's camera/light frame (looking down -Z, +Y up) to look at target."""
    forward = normalize(sub(target, eye))
    right = normalize(cross(forward, list(up)))
    true_up = cross(right, forward)
    return quat_from_matrix([right, true_up, scale(forward, -1.0)])


def y_rotation(degrees):
    half = math.radians(degrees) / 2
    return [0.0, round(math.sin(half), 7), 0.0, round(math.cos(half), 7)]


# ---------------------------------------------------------------------------------------------
# PNG writer (8-bit RGB, no filtering)


def png_bytes(width, height, pixel):
    """pixel(x, y) -> (r, g, b) in 0..255; y = 0 is the top row (glTF's v = 0)."""
    rows = bytearray()
    for y in range(height):
        rows.append(0)
        for x in range(width):
            rows.extend(bytes(pixel(x, y)))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) +
            chunk(b"IDAT", zlib.compress(bytes(rows), 9)) + chunk(b"IEND", b""))


# ---------------------------------------------------------------------------------------------
# Geometry: lists of (position, normal, uv[, tangent]) vertices and triangle indices


class Mesh:
    def __init__(self):
        self.positions, self.normals, self.uvs, self.tangents, self.indices = [], [], [], [], []

    def vertex(self, p, n, uv, tangent=None):
        self.positions.append([float(v) for v in p])
        self.normals.append([float(v) for v in n])
        self.uvs.append([float(v) for v in uv])
        if tangent is not None:
            self.tangents.append([float(v) for v in tangent])
        return len(self.positions) - 1

    def quad(self, corners, facing, uv_scale=(1.0, 1.0), tangent=None):
        """A flat quad (corners in order around it) whose front side faces `facing`."""
        # Newell's normal: the best-fit plane's, also for the slightly non-planar measured walls.
        normal = [0.0, 0.0, 0.0]
        for a, b in zip(corners, corners[1:] + corners[:1]):
            normal = add(normal, cross(a, b))
        normal = normalize(normal)
        if dot(normal, facing) < 0:
            corners = corners[::-1]
            normal = scale(normal, -1.0)
        su, sv = uv_scale
        uvs = [(0, sv), (su, sv), (su, 0), (0, 0)]
        base = [self.vertex(c, normal, uv, tangent) for c, uv in zip(corners, uvs)]
        self.indices += [base[0], base[1], base[2], base[0], base[2], base[3]]


def unit_box():
    """The cube [-0.5, 0.5]³ with outward faces (nodes scale and rotate it)."""
    mesh = Mesh()
    for axis in range(3):
        for sign in (-1.0, 1.0):
            normal = [0.0, 0.0, 0.0]
            normal[axis] = sign
            u_axis, v_axis = [a for a in range(3) if a != axis]
            corners = []
            for du, dv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                c = [0.0, 0.0, 0.0]
                c[axis], c[u_axis], c[v_axis] = 0.5 * sign, 0.5 * du, 0.5 * dv
                corners.append(c)
            mesh.quad(corners, normal)
    return mesh


def uv_sphere(radius, segments, rings):
    mesh = Mesh()
    for j in range(rings + 1):
        theta = math.pi * j / rings
        for i in range(segments + 1):
            phi = 2.0 * math.pi * i / segments
            n = [math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi)]
            n = [round(v, 7) for v in n]
            mesh.vertex(scale(n, radius), n, (i / segments, j / rings))
    for j in range(rings):
        for i in range(segments):
            a = j * (segments + 1) + i
            b = a + segments + 1
            # Counter-clockwise seen from outside; skip the degenerate triangles at the poles.
            if j != 0:
                mesh.indices += [a, b, a + 1]
            if j != rings - 1:
                mesh.indices += [a + 1, b, b + 1]
    return mesh


# ---------------------------------------------------------------------------------------------
# glTF document builder


class Gltf:
    def __init__(self, name):
        self.name = name
        self.binary = bytearray()
        self.doc = {
            "asset": {"version": "2.0", "generator": "chorus scenes/generate_scenes.py",
                      "copyright": "CC0 1.0 (public domain dedication), the chorus authors"},
            "scene": 0, "scenes": [{"name": name, "nodes": []}], "nodes": [], "meshes": [],
            "materials": [], "accessors": [], "bufferViews": [], "buffers": [],
        }
        self.extensions = set()

    def _view(self, data, target):
        while len(self.binary) % 4:
            self.binary.append(0)
        view = {"buffer": 0, "byteOffset": len(self.binary), "byteLength": len(data)}
        if target:
            view["target"] = target
        self.binary.extend(data)
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def _accessor(self, values, kind, component, target, with_bounds=False):
        flat = [v for item in values for v in (item if isinstance(item, list) else [item])]
        fmt = "<%d%s" % (len(flat), "f" if component == FLOAT else "H")
        accessor = {"bufferView": self._view(struct.pack(fmt, *flat), target),
                    "componentType": component, "count": len(values), "type": kind}
        if with_bounds:
            accessor["min"] = [min(v[i] for v in values) for i in range(3)]
            accessor["max"] = [max(v[i] for v in values) for i in range(3)]
        self.doc["accessors"].append(accessor)
        return len(self.doc["accessors"]) - 1

    def geometry(self, mesh):
        """Accessors for a Mesh, shareable by several glTF meshes: (attributes, indices)."""
        attributes = {
            "POSITION": self._accessor(mesh.positions, "VEC3", FLOAT, ARRAY_BUFFER, True),
            "NORMAL": self._accessor(mesh.normals, "VEC3", FLOAT, ARRAY_BUFFER),
            "TEXCOORD_0": self._accessor(mesh.uvs, "VEC2", FLOAT, ARRAY_BUFFER),
        }
        if mesh.tangents:
            attributes["TANGENT"] = self._accessor(mesh.tangents, "VEC4", FLOAT, ARRAY_BUFFER)
        indices = self._accessor(mesh.indices, "SCALAR", UNSIGNED_SHORT, ELEMENT_ARRAY_BUFFER)
        return attributes, indices

    def mesh(self, name, primitives):
        """primitives: list of ((attributes, indices), material index)."""
        self.doc["meshes"].append({"name": name, "primitives": [
            {"attributes": geometry[0], "indices": geometry[1], "material": material}
            for geometry, material in primitives]})
        return len(self.doc["meshes"]) - 1

    def material(self, name, base_color, metallic=0.0, roughness=1.0, extensions=None,
                 **extra):
        material = {"name": name, "pbrMetallicRoughness": {
            "baseColorFactor": list(base_color) + [1.0], "metallicFactor": metallic,
            "roughnessFactor": roughness}}
        material.update(extra)
        if extensions:
            material["extensions"] = extensions
            self.extensions.update(extensions)
        self.doc["materials"].append(material)
        return len(self.doc["materials"]) - 1

    def node(self, name, **fields):
        self.doc["nodes"].append(dict(name=name, **fields))
        index = len(self.doc["nodes"]) - 1
        self.doc["scenes"][0]["nodes"].append(index)
        return index

    def camera(self, name, yfov, aspect, znear=0.01, zfar=100.0):
        self.doc.setdefault("cameras", []).append({"name": name, "type": "perspective",
                                                  "perspective": {"yfov": yfov,
                                                                  "aspectRatio": aspect,
                                                                  "znear": znear,
                                                                  "zfar": zfar}})
        return len(self.doc["cameras"]) - 1

    def texture(self, name, png, uri=None):
        """An image (embedded as a data URI unless `uri` names a file to write) and texture."""
        image = {"name": name}
        if uri is None:
            image["uri"] = "data:image/png;base64," + base64.b64encode(png).decode("ascii")
        else:
            image["uri"] = uri
            self.files = getattr(self, "files", {})
            self.files[uri] = png
        self.doc.setdefault("images", []).append(image)
        if "samplers" not in self.doc:
            self.doc["samplers"] = [{"magFilter": LINEAR, "minFilter": LINEAR_MIPMAP_LINEAR,
                                     "wrapS": REPEAT, "wrapT": REPEAT}]
        self.doc.setdefault("textures", []).append(
            {"name": name, "sampler": 0, "source": len(self.doc["images"]) - 1})
        return len(self.doc["textures"]) - 1

    def write(self, directory, embed_buffer):
        files = dict(getattr(self, "files", {}))
        if embed_buffer:
            uri = "data:application/octet-stream;base64," + base64.b64encode(
                bytes(self.binary)).decode("ascii")
        else:
            uri = self.name + ".bin"
            files[uri] = bytes(self.binary)
        self.doc["buffers"] = [{"byteLength": len(self.binary), "uri": uri}]
        if self.extensions:
            self.doc["extensionsUsed"] = sorted(self.extensions)
        files[self.name + ".gltf"] = (json.dumps(self.doc, indent=1) + "\n").encode("utf-8")
        for file_name, data in sorted(files.items()):
            with open(os.path.join(directory, file_name), "wb") as f:
                f.write(data)
            print("wrote %s (%d bytes)" % (os.path.join(directory, file_name), len(data)))


def lambertian(gltf, name, color, **extra):
    """A pure Lambertian: KHR_materials_specular with specularFactor 0 removes the coating."""
    return gltf.material(name, color, 0.0, 1.0,
                         {"KHR_materials_specular": {"specularFactor": 0.0}}, **extra)


# ---------------------------------------------------------------------------------------------
# Scene 1: the Cornell box (the default scene)
#
# The room and light are the measured Cornell box data (Cornell University Program of Computer
# Graphics, "Cornell Box Data"), in millimetres, scaled to metres. x = 0 is the green wall,
# the camera looks along +z into the open side. The two blocks are unit cubes placed by node
# transforms (size, position and rotation fitted to the measured corners), one mesh instanced
# twice.

CORNELL_WHITE = (0.73, 0.73, 0.73)   # linear reflectances commonly used for the measured data
CORNELL_RED = (0.63, 0.065, 0.05)
CORNELL_GREEN = (0.14, 0.45, 0.091)


def cornell_box(directory):
    mm = 0.001
    gltf = Gltf("cornell-box")
    white = lambertian(gltf, "white", CORNELL_WHITE)
    red = lambertian(gltf, "red", CORNELL_RED)
    green = lambertian(gltf, "green", CORNELL_GREEN)
    # Radiance = emissiveFactor × emissive_strength: (64, 54, 40) W/(m² sr); with
    # the 0.0137 m² light this lights the back wall to ~0.35 and the red wall to ~0.8 (exposure 0).
    light = gltf.material("light", (0.0, 0.0, 0.0), 0.0, 1.0,
                          {"KHR_materials_specular": {"specularFactor": 0.0},
                           "KHR_materials_emissive_strength": {"emissiveStrength": 64.0}},
                          emissiveFactor=[1.0, 0.85, 0.62])

    def pts(*corners):
        return [[c * mm for c in corner] for corner in corners]

    inside = [278.0 * mm, 274.4 * mm, 279.6 * mm]

    def facing_inside(corners):
        centre = scale([sum(c[i] for c in corners) for i in range(3)], 0.25)
        return sub(inside, centre)

    white_mesh, red_mesh, green_mesh = Mesh(), Mesh(), Mesh()
    walls = [
        (white_mesh, pts((552.8, 0, 0), (0, 0, 0), (0, 0, 559.2), (549.6, 0, 559.2))),  # floor
        (white_mesh, pts((556, 548.8, 0), (556, 548.8, 559.2), (0, 548.8, 559.2),
                         (0, 548.8, 0))),  # ceiling
        (white_mesh, pts((549.6, 0, 559.2), (0, 0, 559.2), (0, 548.8, 559.2),
                         (556, 548.8, 559.2))),  # back wall
        (green_mesh, pts((0, 0, 559.2), (0, 0, 0), (0, 548.8, 0), (0, 548.8, 559.2))),
        (red_mesh, pts((552.8, 0, 0), (549.6, 0, 559.2), (556, 548.8, 559.2),
                       (556, 548.8, 0))),
    ]
    for mesh, corners in walls:
        mesh.quad(corners, facing_inside(corners))
    room = gltf.mesh("room", [(gltf.geometry(white_mesh), white),
                              (gltf.geometry(red_mesh), red),
                              (gltf.geometry(green_mesh), green)])
    gltf.node("room", mesh=room)

    block = gltf.mesh("block", [(gltf.geometry(unit_box()), white)])
    measured_blocks = [
        ("short block", 165.0, [(130, 65), (82, 225), (240, 272), (290, 114)]),
        ("tall block", 330.0, [(423, 247), (265, 296), (314, 456), (472, 406)]),
    ]
    for name, height, corners in measured_blocks:
        cx = sum(c[0] for c in corners) / 4
        cz = sum(c[1] for c in corners) / 4
        width = math.dist(corners[0], corners[3])
        depth = math.dist(corners[0], corners[1])
        # Rotation about +y that maps the cube's +x edge onto corners[0] → corners[3].
        ex, ez = corners[3][0] - corners[0][0], corners[3][1] - corners[0][1]
        angle = math.degrees(math.atan2(-ez, ex))
        # A quarter turn of a box is the same box with width and depth swapped: keep the
        # rotation within ±45° so that it reads as the familiar small tilt.
        while angle > 45:
            angle, width, depth = angle - 90, depth, width
        while angle <= -45:
            angle, width, depth = angle + 90, depth, width
        gltf.node(name, mesh=block,
                  translation=[round(cx * mm, 6), round(height / 2 * mm, 6), round(cz * mm, 6)],
                  rotation=y_rotation(angle),
                  scale=[round(width * mm, 6), round(height * mm, 6), round(depth * mm, 6)])

    light_mesh = Mesh()
    light_mesh.quad(pts((343, 548.3, 227), (343, 548.3, 332), (213, 548.3, 332),
                        (213, 548.3, 227)), [0, -1, 0])
    gltf.node("light", mesh=gltf.mesh("light", [(gltf.geometry(light_mesh), light)]))

    # Film 25 mm, focal length 35 mm: yfov = 2 atan(12.5 / 35).
    camera = gltf.camera("camera", 2 * math.atan(12.5 / 35.0), 1.0)
    gltf.node("camera", camera=camera, translation=[0.278, 0.273, -0.8],
              rotation=[0.0, 1.0, 0.0, 0.0])
    gltf.write(directory, embed_buffer=False)


# ---------------------------------------------------------------------------------------------
# Scene 2: glass and metal


def checker_png():
    def pixel(x, y):
        light = ((x // 8) + (y // 8)) % 2 == 0
        return (200, 196, 188) if light else (52, 58, 70)
    return png_bytes(64, 64, pixel)


def glass_and_metal(directory):
    gltf = Gltf("glass-and-metal")
    checker = gltf.texture("checker", checker_png())
    floor_material = gltf.material("checker floor", (1.0, 1.0, 1.0), 0.0, 0.6,
                                   pbr_texture=checker)
    wall_material = gltf.material("wall", (0.6, 0.6, 0.6), 0.0, 0.9)
    glass = gltf.material("glass", (1.0, 1.0, 1.0), 0.0, 0.0, {
        "KHR_materials_transmission": {"transmissionFactor": 1.0},
        "KHR_materials_ior": {"ior": 1.5},
        "KHR_materials_volume": {"thicknessFactor": 0.8, "attenuationDistance": 1.5,
                                 "attenuationColor": [0.85, 0.95, 1.0]}})
    gold = gltf.material("smooth gold", (1.0, 0.78, 0.34), 1.0, 0.0)
    copper = gltf.material("rough copper", (0.95, 0.64, 0.54), 1.0, 0.35)
    light = gltf.material("small light", (0.0, 0.0, 0.0), 0.0, 1.0,
                          {"KHR_materials_emissive_strength": {"emissiveStrength": 1000.0}},
                          emissiveFactor=[1.0, 0.95, 0.9])

    floor = Mesh()
    floor.quad([[-3, 0, 3], [3, 0, 3], [3, 0, -3], [-3, 0, -3]], [0, 1, 0], uv_scale=(6, 6))
    gltf.node("floor", mesh=gltf.mesh("floor", [(gltf.geometry(floor), floor_material)]))
    wall = Mesh()
    wall.quad([[-3, 0, -2], [3, 0, -2], [3, 3, -2], [-3, 3, -2]], [0, 0, 1])
    gltf.node("back wall", mesh=gltf.mesh("back wall", [(gltf.geometry(wall), wall_material)]))

    radius = 0.4
    sphere = gltf.geometry(uv_sphere(radius, 40, 20))
    for name, material, position in (("glass sphere", glass, [0.0, radius, 0.2]),
                                     ("smooth gold sphere", gold, [-1.0, radius, -0.5]),
                                     ("rough copper sphere", copper, [1.0, radius, -0.5])):
        gltf.node(name, mesh=gltf.mesh(name, [(sphere, material)]), translation=position)

    emitter = Mesh()
    size = 0.075
    emitter.quad([[-size, 0, -size], [size, 0, -size], [size, 0, size], [-size, 0, size]],
                 [0, -1, 0])
    gltf.node("small light", mesh=gltf.mesh("small light", [(gltf.geometry(emitter), light)]),
              translation=[0.35, 2.0, 0.9])

    eye = [0.0, 1.3, 3.4]
    camera = gltf.camera("camera", math.radians(40.0), 1.5)
    gltf.node("camera", camera=camera, translation=eye,
              rotation=look_at_rotation(eye, [0.0, 0.35, -0.1]))
    _attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


def _attach_base_color_textures(gltf):
    """Moves the builder's `pbr_texture` shorthand into pbrMetallicRoughness."""
    for material in gltf.doc["materials"]:
        texture = material.pop("pbr_texture", None)
        if texture is not None:
            material["pbrMetallicRoughness"]["baseColorTexture"] = {"index": texture}


# ---------------------------------------------------------------------------------------------
# Scene 3: punctual lights and a normal-mapped floor

BRICK_W, BRICK_H, MORTAR = 32, 16, 2  # texels; the 128² texture holds 4 × 8 bricks


def brick_height(x, y):
    """1 on a brick's face, 0 in the mortar, with a 3-texel bevel in between."""
    row = y // BRICK_H
    xs = (x + (BRICK_W // 2 if row % 2 else 0)) % 128
    dx = min(xs % BRICK_W, BRICK_W - 1 - xs % BRICK_W) - MORTAR + 1
    dy = min(y % BRICK_H, BRICK_H - 1 - y % BRICK_H) - MORTAR + 1
    return max(0.0, min(1.0, min(dx, dy) / 3.0))


def brick_color_png():
    def pixel(x, y):
        h = brick_height(x, y)
        row, col = y // BRICK_H, (x + (BRICK_W // 2 if (y // BRICK_H) % 2 else 0)) // BRICK_W
        shade = 0.85 + 0.15 * (((row * 7 + col * 13) % 5) / 4.0)
        brick = (int(170 * shade), int(78 * shade), int(56 * shade))
        mortar = (150, 146, 138)
        return tuple(int(mortar[i] + (brick[i] - mortar[i]) * min(1.0, h * 3)) for i in range(3))
    return png_bytes(128, 128, pixel)


def brick_normal_png():
    strength = 2.0
    def pixel(x, y):
        # Central differences of the height field, wrapping like the texture does. Tangent-space
        # normal: +x along +u, +y towards decreasing v (up in the image), as glTF expects.
        dhdx = (brick_height((x + 1) % 128, y) - brick_height((x - 1) % 128, y)) / 2
        dhdy = (brick_height(x, (y + 1) % 128) - brick_height(x, (y - 1) % 128)) / 2
        n = normalize([-strength * dhdx, strength * dhdy, 1.0])
        return tuple(int(round((v * 0.5 + 0.5) * 255)) for v in n)
    return png_bytes(128, 128, pixel)


def punctual_lights(directory):
    gltf = Gltf("punctual-lights")
    color = gltf.texture("brick color", brick_color_png(), uri="punctual-lights-brick-color.png")
    normal = gltf.texture("brick normal", brick_normal_png(),
                          uri="punctual-lights-brick-normal.png")
    floor_material = gltf.material("brick floor", (1.0, 1.0, 1.0), 0.0, 0.8,
                                   pbr_texture=color,
                                   normalTexture={"index": normal, "scale": 1.0})
    wall_material = gltf.material("wall", (0.7, 0.7, 0.68), 0.0, 0.9)
    sphere_material = gltf.material("blue plastic", (0.1, 0.25, 0.6), 0.0, 0.3)
    box_material = gltf.material("brushed steel", (0.8, 0.8, 0.82), 1.0, 0.45)

    floor = Mesh()
    # The tangent (+u = +x, w = 1 so the bitangent is −z, towards decreasing v) is given so that
    # the normal map needs no tangent generation.
    floor.quad([[-2, 0, 2], [2, 0, 2], [2, 0, -2], [-2, 0, -2]], [0, 1, 0], uv_scale=(4, 4),
               tangent=[1.0, 0.0, 0.0, 1.0])
    gltf.node("floor", mesh=gltf.mesh("floor", [(gltf.geometry(floor), floor_material)]))
    wall = Mesh()
    wall.quad([[-2, 0, -1.5], [2, 0, -1.5], [2, 2.5, -1.5], [-2, 2.5, -1.5]], [0, 0, 1])
    gltf.node("back wall", mesh=gltf.mesh("back wall", [(gltf.geometry(wall), wall_material)]))
    gltf.node("sphere", mesh=gltf.mesh("sphere", [(gltf.geometry(uv_sphere(0.35, 32, 16)),
                                                   sphere_material)]),
              translation=[0.55, 0.35, 0.0])
    gltf.node("box", mesh=gltf.mesh("box", [(gltf.geometry(unit_box()), box_material)]),
              translation=[-0.6, 0.25, -0.2], rotation=y_rotation(30.0),
              scale=[0.5, 0.5, 0.5])

    # KHR_lights_punctual: intensity in candela; lights shine down their node's −z.
    gltf.doc["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"name": "spot", "type": "spot", "color": [1.0, 0.97, 0.9], "intensity": 50.0,
         "spot": {"innerConeAngle": 0.25, "outerConeAngle": 0.45}},
        {"name": "fill", "type": "point", "color": [1.0, 0.8, 0.6], "intensity": 5.0},
    ]}}
    gltf.extensions.add("KHR_lights_punctual")
    spot_position = [-1.0, 2.5, 1.0]
    gltf.node("spot light", translation=spot_position,
              rotation=look_at_rotation(spot_position, [0.0, 0.0, 0.0]),
              extensions={"KHR_lights_punctual": {"light": 0}})
    gltf.node("point light", translation=[1.2, 1.2, 1.0],
              extensions={"KHR_lights_punctual": {"light": 1}})

    eye = [0.0, 1.6, 3.5]
    camera = gltf.camera("camera", math.radians(43.0), 1.5)
    gltf.node("camera", camera=camera, translation=eye,
              rotation=look_at_rotation(eye, [0.0, 0.3, 0.0]))
    _attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=False)


# ---------------------------------------------------------------------------------------------
# Scene 4: stiff caustics
#
# The stiff case of denoising: an 8 cm emitter of radiance 600 sealed inside a solid glass ball.
# Shadow rays do not pass glass, so everything it lights is found by BSDF sampling alone: a
# diffuse bounce that happens to refract through the ball onto the emitter, a sample thousands
# of times the pixel's mean. A large dim ceiling light gives the smooth part of the image (and
# its own caustic under the second, clear glass sphere).


def stiff_caustics(directory):
    gltf = Gltf("stiff-caustics")
    floor_material = lambertian(gltf, "floor", (0.7, 0.68, 0.64))
    wall_material = lambertian(gltf, "wall", (0.55, 0.6, 0.7))
    glass = gltf.material("glass", (1.0, 1.0, 1.0), 0.0, 0.0, {
        "KHR_materials_transmission": {"transmissionFactor": 1.0},
        "KHR_materials_ior": {"ior": 1.5}})
    gold = gltf.material("rough gold", (1.0, 0.78, 0.34), 1.0, 0.25)
    ember = gltf.material("ember", (0.0, 0.0, 0.0), 0.0, 1.0,
                          {"KHR_materials_specular": {"specularFactor": 0.0},
                           "KHR_materials_emissive_strength": {"emissiveStrength": 600.0}},
                          emissiveFactor=[1.0, 0.8, 0.55])
    fill = gltf.material("ceiling light", (0.0, 0.0, 0.0), 0.0, 1.0,
                         {"KHR_materials_specular": {"specularFactor": 0.0},
                          "KHR_materials_emissive_strength": {"emissiveStrength": 3.0}},
                         emissiveFactor=[0.9, 0.95, 1.0])

    floor = Mesh()
    floor.quad([[-3, 0, 3], [3, 0, 3], [3, 0, -3], [-3, 0, -3]], [0, 1, 0])
    gltf.node("floor", mesh=gltf.mesh("floor", [(gltf.geometry(floor), floor_material)]))
    wall = Mesh()
    wall.quad([[-3, 0, -1.5], [3, 0, -1.5], [3, 3, -1.5], [-3, 3, -1.5]], [0, 0, 1])
    gltf.node("back wall", mesh=gltf.mesh("back wall", [(gltf.geometry(wall), wall_material)]))
    ceiling = Mesh()
    ceiling.quad([[-1, 3, -1], [1, 3, -1], [1, 3, 1], [-1, 3, 1]], [0, -1, 0])
    gltf.node("ceiling light", mesh=gltf.mesh("ceiling light",
                                              [(gltf.geometry(ceiling), fill)]))

    ball = 0.28
    gltf.node("glass ball", mesh=gltf.mesh("glass ball", [(gltf.geometry(uv_sphere(ball, 48, 24)),
                                                            glass)]),
              translation=[-0.45, ball, 0.0])
    gltf.node("ember", mesh=gltf.mesh("ember", [(gltf.geometry(uv_sphere(0.04, 16, 8)), ember)]),
              translation=[-0.45, ball, 0.0])
    sphere = 0.3
    gltf.node("clear sphere", mesh=gltf.mesh("clear sphere",
                                             [(gltf.geometry(uv_sphere(sphere, 48, 24)), glass)]),
              translation=[0.5, sphere, 0.35])
    gltf.node("gold sphere", mesh=gltf.mesh("gold sphere",
                                            [(gltf.geometry(uv_sphere(0.22, 32, 16)), gold)]),
              translation=[0.35, 0.22, -0.7])

    eye = [0.0, 0.95, 1.9]
    camera = gltf.camera("camera", math.radians(40.0), 1.0)
    gltf.node("camera", camera=camera, translation=eye,
              rotation=look_at_rotation(eye, [0.0, 0.25, -0.15]))
    gltf.write(directory, embed_buffer=True)


def main():
    directory = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    cornell_box(directory)
    glass_and_metal(directory)
    punctual_lights(directory)
    stiff_caustics(directory)


if __name__ == "__main__":
    main()
