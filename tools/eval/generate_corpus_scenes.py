#!/usr/bin/env python3
"""Writes the generated scenes of the evaluation corpus (Python 3 standard library only).

    python3 tools/eval/generate_corpus_scenes.py OUTPUT_DIR

Variants of what the project's own scenes show, each stressing the denoisers differently:
materials, light sizes and positions, glossy and glass objects, textured floors and an interior
lit through a doorway (tools/eval/corpus.json says which half each belongs to and why). The
camera is a pinhole (renderer/integrator/camera.h), so there is no depth-of-field variant.
Everything is deterministic: the same files on every run. Reuses the glTF builder of
scenes/generate_scenes.py.
"""
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scenes"))
import generate_scenes as gs  # noqa: E402  (the project's glTF builder)

SCENES = {}


def scene(function):
    """Registers a scene writer under its name with underscores as dashes."""
    SCENES[function.__name__.replace("_", "-")] = function
    return function


def emissive(gltf, name, color, strength):
    return gltf.material(name, (0.0, 0.0, 0.0), 0.0, 1.0,
                         {"KHR_materials_emissive_strength": {"emissiveStrength": strength}},
                         emissiveFactor=list(color))


def glass(gltf, name, tint=(1.0, 1.0, 1.0), volume=True):
    extensions = {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                  "KHR_materials_ior": {"ior": 1.5}}
    if volume:
        extensions["KHR_materials_volume"] = {"thicknessFactor": 0.5, "attenuationDistance": 1.0,
                                              "attenuationColor": list(tint)}
    return gltf.material(name, (1.0, 1.0, 1.0), 0.0, 0.0, extensions)


def add_quad(gltf, name, corners, facing, material, uv_scale=(1.0, 1.0), tangent=None):
    mesh = gs.Mesh()
    mesh.quad([list(map(float, c)) for c in corners], facing, uv_scale, tangent)
    gltf.node(name, mesh=gltf.mesh(name, [(gltf.geometry(mesh), material)]))


def add_sphere(gltf, name, material, centre, radius):
    # One set of accessors per radius and document, shared by the spheres of that size.
    spheres = gltf.__dict__.setdefault("sphere_geometry", {})
    if radius not in spheres:
        spheres[radius] = gltf.geometry(gs.uv_sphere(radius, 40, 20))
    gltf.node(name, mesh=gltf.mesh(name, [(spheres[radius], material)]),
              translation=list(centre))


def add_box(gltf, name, material, centre, size, yaw=0.0):
    gltf.node(name, mesh=gltf.mesh(name, [(gltf.geometry(gs.unit_box()), material)]),
              translation=list(centre), rotation=gs.y_rotation(yaw), scale=list(size))


def add_camera(gltf, eye, target, yfov_degrees, aspect):
    camera = gltf.camera("camera", math.radians(yfov_degrees), aspect)
    gltf.node("camera", camera=camera, translation=list(eye),
              rotation=gs.look_at_rotation(eye, target))


def textured(gltf, name, png, roughness=0.8, metallic=0.0):
    material = gltf.material(name, (1.0, 1.0, 1.0), metallic, roughness,
                             pbr_texture=gltf.texture(name, png))
    return material


# ---------------------------------------------------------------------------------------------
# Procedural textures (small, embedded as data URIs)


def fine_checker_png(size=128, period=4):
    def pixel(x, y):
        on = ((x // period) + (y // period)) % 2 == 0
        return (210, 205, 190) if on else (40, 48, 60)
    return gs.png_bytes(size, size, pixel)


def planks_png(size=128):
    """Wood-like planks: bands of different tone with grain lines (high-frequency detail)."""
    def pixel(x, y):
        plank = y // 16
        tone = 0.75 + 0.25 * ((plank * 37) % 7) / 6.0
        grain = 0.85 + 0.15 * math.sin(0.9 * x + 3.0 * math.sin(0.13 * x + plank))
        gap = 0.35 if y % 16 == 0 else 1.0
        s = tone * grain * gap
        return (int(170 * s), int(118 * s), int(72 * s))
    return gs.png_bytes(size, size, pixel)


def noise_png(size=128):
    """Hash noise in blocks of 2 texels: a texture no feature-free filter can keep."""
    def value(x, y):
        k = (x // 2) * 73856093 ^ (y // 2) * 19349663
        k = (k ^ (k >> 13)) * 1274126177 & 0xFFFFFFFF
        return (k >> 8 & 0xFF) / 255.0

    def pixel(x, y):
        v = 0.25 + 0.75 * value(x, y)
        return (int(200 * v), int(190 * v), int(160 * v))
    return gs.png_bytes(size, size, pixel)


# ---------------------------------------------------------------------------------------------
# Scenes


@scene
def interior_doorway(directory):
    """A closed room lit only through a doorway by a bright panel outside: direct light reaches a
    door-shaped patch of floor and wall, every other pixel is lit through at least one bounce
    (the issue-25 case where the noisy fallback left black speckle at 4 spp)."""
    gltf = gs.Gltf("interior-doorway")
    wall = gs.lambertian(gltf, "wall", (0.75, 0.74, 0.7))
    floor = textured(gltf, "plank floor", planks_png(), roughness=0.6)
    sofa = gs.lambertian(gltf, "blue cloth", (0.15, 0.25, 0.55))
    brass = gltf.material("brass", (0.9, 0.7, 0.35), 1.0, 0.3)
    light = emissive(gltf, "daylight", (1.0, 0.95, 0.85), 40.0)
    w, d, h = 2.0, 2.0, 2.6  # half width (x), half depth (z), height
    door_z0, door_z1, door_h = -0.5, 0.5, 2.1
    inside = (0, 1, 0)
    add_quad(gltf, "floor", [(-w, 0, d), (w, 0, d), (w, 0, -d), (-w, 0, -d)], inside, floor,
             uv_scale=(3, 3))
    add_quad(gltf, "ceiling", [(-w, h, -d), (w, h, -d), (w, h, d), (-w, h, d)], (0, -1, 0), wall)
    add_quad(gltf, "back wall", [(-w, 0, -d), (w, 0, -d), (w, h, -d), (-w, h, -d)], (0, 0, 1), wall)
    add_quad(gltf, "front wall", [(-w, 0, d), (w, 0, d), (w, h, d), (-w, h, d)], (0, 0, -1), wall)
    add_quad(gltf, "left wall", [(-w, 0, -d), (-w, 0, d), (-w, h, d), (-w, h, -d)], (1, 0, 0), wall)
    # The right wall (x = +w) around the door opening: three quads.
    add_quad(gltf, "right wall a", [(w, 0, -d), (w, 0, door_z0), (w, h, door_z0), (w, h, -d)],
             (-1, 0, 0), wall)
    add_quad(gltf, "right wall b", [(w, 0, door_z1), (w, 0, d), (w, h, d), (w, h, door_z1)],
             (-1, 0, 0), wall)
    add_quad(gltf, "right wall lintel", [(w, door_h, door_z0), (w, door_h, door_z1),
                                         (w, h, door_z1), (w, h, door_z0)], (-1, 0, 0), wall)
    # Outside: ground and a large bright panel facing the door, low enough to shine inside.
    add_quad(gltf, "outside ground", [(w, 0, -3), (w + 3, 0, -3), (w + 3, 0, 3), (w, 0, 3)],
             (0, 1, 0), wall)
    add_quad(gltf, "daylight panel", [(w + 2.5, 0.2, -2.5), (w + 2.5, 0.2, 2.5),
                                      (w + 2.5, 4.0, 2.5), (w + 2.5, 4.0, -2.5)], (-1, 0, 0), light)
    add_box(gltf, "sofa", sofa, (-1.2, 0.3, -1.2), (1.4, 0.6, 0.7), yaw=10.0)
    add_sphere(gltf, "brass ball", brass, (0.3, 0.25, 0.4), 0.25)
    add_camera(gltf, (-1.7, 1.5, 1.7), (0.9, 0.8, -0.9), 65.0, 1.5)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


@scene
def material_zoo(directory):
    """Spheres from mirror-like to rough metal, glossy and matte plastic and glass on a fine
    checker floor, under one large soft area light."""
    gltf = gs.Gltf("material-zoo")
    floor = textured(gltf, "fine checker", fine_checker_png(), roughness=0.5)
    wall = gs.lambertian(gltf, "wall", (0.55, 0.55, 0.58))
    light = emissive(gltf, "soft panel", (1.0, 0.97, 0.92), 6.0)
    add_quad(gltf, "floor", [(-4, 0, 3), (4, 0, 3), (4, 0, -3), (-4, 0, -3)], (0, 1, 0), floor,
             uv_scale=(4, 3))
    add_quad(gltf, "back wall", [(-4, 0, -2), (4, 0, -2), (4, 4, -2), (-4, 4, -2)], (0, 0, 1), wall)
    add_quad(gltf, "soft panel", [(-1.5, 3.0, -1.0), (1.5, 3.0, -1.0), (1.5, 3.0, 1.5),
                                  (-1.5, 3.0, 1.5)], (0, -1, 0), light)
    spheres = [
        ("mirror silver", gltf.material("mirror silver", (0.95, 0.95, 0.95), 1.0, 0.02)),
        ("glossy gold", gltf.material("glossy gold", (1.0, 0.78, 0.34), 1.0, 0.15)),
        ("rough aluminium", gltf.material("rough aluminium", (0.9, 0.9, 0.92), 1.0, 0.5)),
        ("red plastic", gltf.material("red plastic", (0.7, 0.08, 0.05), 0.0, 0.1)),
        ("matte green", gs.lambertian(gltf, "matte green", (0.2, 0.5, 0.15))),
        ("glass", glass(gltf, "glass", (0.9, 1.0, 0.95))),
    ]
    for i, (name, material) in enumerate(spheres):
        x = -1.9 + 0.76 * i
        add_sphere(gltf, name, material, (x, 0.33, -0.2 + 0.3 * (i % 2)), 0.33)
    add_camera(gltf, (0.0, 1.5, 4.2), (0.0, 0.35, -0.2), 40.0, 1.5)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


@scene
def glass_caustics(directory):
    """Glass sphere, glass slab and a coloured glass block lit by a tiny, very bright light low
    at the side: caustics on a textured floor and fireflies in every sample count."""
    gltf = gs.Gltf("glass-caustics")
    floor = textured(gltf, "noise floor", noise_png(), roughness=0.9)
    wall = gs.lambertian(gltf, "wall", (0.6, 0.6, 0.6))
    light = emissive(gltf, "tiny light", (1.0, 0.9, 0.75), 3000.0)
    add_quad(gltf, "floor", [(-3, 0, 3), (3, 0, 3), (3, 0, -3), (-3, 0, -3)], (0, 1, 0), floor,
             uv_scale=(5, 5))
    add_quad(gltf, "back wall", [(-3, 0, -1.5), (3, 0, -1.5), (3, 3, -1.5), (-3, 3, -1.5)],
             (0, 0, 1), wall)
    add_sphere(gltf, "glass sphere", glass(gltf, "clear glass"), (-0.5, 0.4, 0.0), 0.4)
    add_box(gltf, "glass slab", glass(gltf, "thin glass", volume=False), (0.55, 0.35, -0.3),
            (0.08, 0.7, 0.6), yaw=-25.0)
    add_box(gltf, "amber block", glass(gltf, "amber glass", (1.0, 0.6, 0.2)), (0.6, 0.15, 0.5),
            (0.3, 0.3, 0.3), yaw=15.0)
    size, x, y, z = 0.03, -1.2, 1.3, 0.6
    add_quad(gltf, "tiny light", [(x - size, y, z - size), (x + size, y, z - size),
                                  (x + size, y, z + size), (x - size, y, z + size)], (0, -1, 0),
             light)
    add_camera(gltf, (0.3, 1.6, 2.8), (0.0, 0.3, -0.1), 40.0, 1.5)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


def cornell_room(gltf, floor_material=None):
    """The project's Cornell room walls (2 m cube, open towards the camera) in simple metres."""
    white = gs.lambertian(gltf, "white", gs.CORNELL_WHITE)
    red = gs.lambertian(gltf, "red", gs.CORNELL_RED)
    green = gs.lambertian(gltf, "green", gs.CORNELL_GREEN)
    s = 1.0
    add_quad(gltf, "floor", [(-s, 0, s), (s, 0, s), (s, 0, -s), (-s, 0, -s)], (0, 1, 0),
             floor_material if floor_material is not None else white, uv_scale=(2, 2))
    add_quad(gltf, "ceiling", [(-s, 2 * s, -s), (s, 2 * s, -s), (s, 2 * s, s), (-s, 2 * s, s)],
             (0, -1, 0), white)
    add_quad(gltf, "back", [(-s, 0, -s), (s, 0, -s), (s, 2 * s, -s), (-s, 2 * s, -s)], (0, 0, 1),
             white)
    add_quad(gltf, "left", [(-s, 0, -s), (-s, 0, s), (-s, 2 * s, s), (-s, 2 * s, -s)], (1, 0, 0),
             red)
    add_quad(gltf, "right", [(s, 0, -s), (s, 0, s), (s, 2 * s, s), (s, 2 * s, -s)], (-1, 0, 0),
             green)
    add_camera(gltf, (0.0, 1.0, 3.9), (0.0, 1.0, 0.0), 37.0, 1.0)
    return white


@scene
def cornell_big_light_glossy(directory):
    """The Cornell room under a ceiling-wide light (soft shadows, little noise in direct light)
    with a glossy metal block and a glass sphere: the noise is in the reflections."""
    gltf = gs.Gltf("cornell-big-light-glossy")
    cornell_room(gltf)
    light = emissive(gltf, "ceiling light", (1.0, 0.9, 0.75), 3.0)
    add_quad(gltf, "ceiling light", [(-0.8, 1.995, -0.8), (0.8, 1.995, -0.8), (0.8, 1.995, 0.8),
                                     (-0.8, 1.995, 0.8)], (0, -1, 0), light)
    add_box(gltf, "chrome block", gltf.material("chrome", (0.9, 0.9, 0.9), 1.0, 0.08),
            (-0.35, 0.6, -0.35), (0.55, 1.2, 0.55), yaw=20.0)
    add_sphere(gltf, "glass sphere", glass(gltf, "glass"), (0.4, 0.35, 0.3), 0.35)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


@scene
def cornell_side_light_textured(directory):
    """The Cornell room with a small light high on the side wall (hard shadows, most of the room
    lit indirectly) and a plank floor; matte blocks."""
    gltf = gs.Gltf("cornell-side-light-textured")
    white = cornell_room(gltf, textured(gltf, "planks", planks_png(), roughness=0.7))
    light = emissive(gltf, "side light", (1.0, 0.85, 0.6), 150.0)
    size = 0.08
    add_quad(gltf, "side light", [(0.995, 1.7 - size, -0.5 - size), (0.995, 1.7 - size, -0.5 + size),
                                  (0.995, 1.7 + size, -0.5 + size), (0.995, 1.7 + size, -0.5 - size)],
             (-1, 0, 0), light)
    add_box(gltf, "tall block", white, (-0.35, 0.6, -0.3), (0.5, 1.2, 0.5), yaw=-18.0)
    add_box(gltf, "short block", white, (0.35, 0.3, 0.35), (0.5, 0.6, 0.5), yaw=17.0)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


@scene
def punctual_textured(directory):
    """Three coloured point and spot lights at different heights over a noise-textured floor and
    textured spheres: sharp shadows from point sources, texture detail everywhere."""
    gltf = gs.Gltf("punctual-textured")
    floor = textured(gltf, "noise floor", noise_png(), roughness=0.7)
    checker = textured(gltf, "checker ball", fine_checker_png(64, 4), roughness=0.4)
    wall = textured(gltf, "plank wall", planks_png(), roughness=0.9)
    add_quad(gltf, "floor", [(-3, 0, 3), (3, 0, 3), (3, 0, -3), (-3, 0, -3)], (0, 1, 0), floor,
             uv_scale=(4, 4))
    add_quad(gltf, "back wall", [(-3, 0, -1.5), (3, 0, -1.5), (3, 3, -1.5), (-3, 3, -1.5)],
             (0, 0, 1), wall, uv_scale=(3, 1.5))
    add_sphere(gltf, "checker ball", checker, (-0.6, 0.4, 0.0), 0.4)
    add_box(gltf, "copper box", gltf.material("copper", (0.95, 0.64, 0.54), 1.0, 0.25),
            (0.7, 0.3, -0.3), (0.6, 0.6, 0.6), yaw=35.0)
    gltf.doc["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"name": "warm spot", "type": "spot", "color": [1.0, 0.8, 0.55], "intensity": 40.0,
         "spot": {"innerConeAngle": 0.15, "outerConeAngle": 0.4}},
        {"name": "blue point", "type": "point", "color": [0.4, 0.6, 1.0], "intensity": 6.0},
        {"name": "low red point", "type": "point", "color": [1.0, 0.3, 0.2], "intensity": 1.5},
    ]}}
    gltf.extensions.add("KHR_lights_punctual")
    spot = [1.5, 2.8, 1.5]
    gltf.node("warm spot", translation=spot, rotation=gs.look_at_rotation(spot, [-0.3, 0, 0]),
              extensions={"KHR_lights_punctual": {"light": 0}})
    gltf.node("blue point", translation=[-1.8, 1.8, 0.8],
              extensions={"KHR_lights_punctual": {"light": 1}})
    gltf.node("low red point", translation=[0.1, 0.25, 1.0],
              extensions={"KHR_lights_punctual": {"light": 2}})
    add_camera(gltf, (0.0, 1.5, 3.4), (0.0, 0.4, -0.2), 42.0, 1.5)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


@scene
def env_objects(directory):
    """No lights: objects on a ground plane for environment lighting (a sky or a studio map):
    glass, glossy and rough metal, a textured matte sphere."""
    gltf = gs.Gltf("env-objects")
    ground = textured(gltf, "plank ground", planks_png(), roughness=0.6)
    add_quad(gltf, "ground", [(-6, 0, 6), (6, 0, 6), (6, 0, -6), (-6, 0, -6)], (0, 1, 0), ground,
             uv_scale=(8, 8))
    add_sphere(gltf, "glass", glass(gltf, "glass", (0.85, 0.95, 1.0)), (-1.0, 0.45, 0.2), 0.45)
    add_sphere(gltf, "chrome", gltf.material("chrome", (0.95, 0.95, 0.95), 1.0, 0.05),
               (0.0, 0.45, -0.4), 0.45)
    add_sphere(gltf, "rough gold", gltf.material("rough gold", (1.0, 0.78, 0.34), 1.0, 0.4),
               (1.0, 0.45, 0.2), 0.45)
    add_box(gltf, "matte box", textured(gltf, "checker box", fine_checker_png(64, 8), 1.0),
            (0.1, 0.25, 0.9), (0.5, 0.5, 0.5), yaw=30.0)
    add_camera(gltf, (0.0, 1.3, 4.0), (0.0, 0.4, 0.0), 38.0, 1.5)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


# ---------------------------------------------------------------------------------------------
# Small and thin lights seen directly or in mirrors (added 2026-12-07, thirteenth session: the
# first four, never tuned on, broke the guard's spread, NFOR and SBF; docs/outliers.md)


@scene
def plastic_two_lights(directory):
    """Issue 28's Tungsten case rebuilt: a smooth and a rough plastic sphere on a checker floor
    under two coloured quad lights: large specular highlights on the smooth sphere."""
    gltf = gs.Gltf("plastic-two-lights")
    floor = textured(gltf, "checker", fine_checker_png(128, 8), roughness=0.7)
    add_quad(gltf, "floor", [(-4, 0, 4), (4, 0, 4), (4, 0, -4), (-4, 0, -4)], (0, 1, 0), floor,
             uv_scale=(4, 4))
    add_sphere(gltf, "smooth", gltf.material("smooth plastic", (0.7, 0.1, 0.1), 0.0, 0.05),
               (-0.6, 0.5, 0.0), 0.5)
    add_sphere(gltf, "rough", gltf.material("rough plastic", (0.1, 0.3, 0.7), 0.0, 0.45),
               (0.6, 0.5, -0.2), 0.5)
    for name, colour, x in (("warm", (1.0, 0.6, 0.3), -1.8), ("cool", (0.3, 0.6, 1.0), 1.8)):
        add_quad(gltf, name, [(x - 0.3, 2.0, -0.3), (x + 0.3, 2.0, -0.3), (x + 0.3, 2.0, 0.3),
                              (x - 0.3, 2.0, 0.3)], (0, -1, 0), emissive(gltf, name, colour, 25.0))
    add_camera(gltf, (0.0, 1.4, 3.2), (0.0, 0.4, 0.0), 40.0, 1.5)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


@scene
def slit_glossy_floor(directory):
    """The Cornell room lit by a slit light two pixels high on the back wall, seen directly, over
    a dark glossy floor: at 4 spp most of the slit's pixels are partly covered."""
    gltf = gs.Gltf("slit-glossy-floor")
    white = cornell_room(gltf, gltf.material("dark gloss", (0.08, 0.08, 0.09), 0.0, 0.12))
    add_quad(gltf, "slit", [(-0.7, 1.6, -0.995), (0.7, 1.6, -0.995), (0.7, 1.62, -0.995),
                            (-0.7, 1.62, -0.995)], (0, 0, 1),
             emissive(gltf, "slit", (1.0, 0.95, 0.9), 400.0))
    add_box(gltf, "block", white, (0.3, 0.3, 0.0), (0.4, 0.6, 0.4), yaw=30.0)
    add_sphere(gltf, "ball", gs.lambertian(gltf, "matte yellow", (0.8, 0.7, 0.2)),
               (-0.4, 0.25, 0.3), 0.25)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


def small_lamps(gltf, colours, positions, radius, strength):
    for i, (colour, position) in enumerate(zip(colours, positions)):
        add_sphere(gltf, "lamp %d" % i, emissive(gltf, "lamp %d" % i, colour, strength), position,
                   radius)


@scene
def night_lamps(directory):
    """Five small, very bright coloured lamps over a plank ground at night, a crate and a chrome
    sphere that mirrors them: tiny lights seen directly and in a mirror."""
    gltf = gs.Gltf("night-lamps")
    ground = textured(gltf, "planks", planks_png(), roughness=0.6)
    add_quad(gltf, "ground", [(-5, 0, 5), (5, 0, 5), (5, 0, -5), (-5, 0, -5)], (0, 1, 0), ground,
             uv_scale=(6, 6))
    small_lamps(gltf, [(1, 0.5, 0.2), (0.3, 0.5, 1), (0.4, 1, 0.4), (1, 0.3, 0.6), (1, 1, 0.8)],
                [(-1.2, 0.9, -0.5), (0.9, 1.4, -1.0), (0.2, 0.4, 0.6), (-0.4, 1.8, -1.6),
                 (1.5, 0.3, 0.4)], 0.04, 300.0)
    add_box(gltf, "crate", gs.lambertian(gltf, "grey", (0.5, 0.5, 0.5)), (-0.3, 0.3, -0.4),
            (0.6, 0.6, 0.6), yaw=20.0)
    add_sphere(gltf, "chrome", gltf.material("chrome", (0.95, 0.95, 0.95), 1.0, 0.05),
               (0.6, 0.35, 0.1), 0.35)
    add_camera(gltf, (0.0, 1.2, 3.5), (0.0, 0.5, -0.3), 45.0, 1.5)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


@scene
def mirror_room(directory):
    """The Cornell room with a mirror on the left wall, a small ceiling light, a rough gold
    sphere and a green glass block: long specular chains."""
    gltf = gs.Gltf("mirror-room")
    cornell_room(gltf)
    add_quad(gltf, "mirror", [(-0.99, 0.2, -0.8), (-0.99, 0.2, 0.6), (-0.99, 1.8, 0.6),
                              (-0.99, 1.8, -0.8)], (1, 0, 0),
             gltf.material("mirror", (0.95, 0.95, 0.95), 1.0, 0.02))
    s = 0.15
    add_quad(gltf, "light", [(-s, 1.995, -s), (s, 1.995, -s), (s, 1.995, s), (-s, 1.995, s)],
             (0, -1, 0), emissive(gltf, "light", (1.0, 0.9, 0.8), 60.0))
    add_sphere(gltf, "gold", gltf.material("gold", (1.0, 0.78, 0.34), 1.0, 0.25), (0.3, 0.4, 0.0),
               0.4)
    add_box(gltf, "glass block", glass(gltf, "glass", (0.9, 1.0, 0.9)), (-0.4, 0.3, 0.4),
            (0.35, 0.6, 0.35), yaw=25.0)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


@scene
def window_bars(directory):
    """A room whose back wall holds three thin, bright vertical light bars (a window's panes
    between mullions) seen directly, a brushed-metal sphere and a glossy box on a plank floor."""
    gltf = gs.Gltf("window-bars")
    cornell_room(gltf, textured(gltf, "planks", planks_png(), roughness=0.5))
    bar = emissive(gltf, "daylight bar", (0.9, 0.95, 1.0), 120.0)
    for i, x in enumerate((-0.45, -0.05, 0.35)):
        add_quad(gltf, "bar %d" % i, [(x, 0.7, -0.995), (x + 0.035, 0.7, -0.995),
                                      (x + 0.035, 1.7, -0.995), (x, 1.7, -0.995)], (0, 0, 1), bar)
    add_sphere(gltf, "brushed", gltf.material("brushed steel", (0.8, 0.8, 0.82), 1.0, 0.15),
               (-0.35, 0.35, 0.2), 0.35)
    add_box(gltf, "glossy box", gltf.material("glossy red", (0.6, 0.08, 0.06), 0.0, 0.1),
            (0.4, 0.25, 0.3), (0.4, 0.5, 0.4), yaw=-25.0)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


@scene
def chrome_candles(directory):
    """Seven tiny warm lamps (candle flames) around a chrome ball, a glass sphere and a gold
    cylinder-like box on a noise-textured table, nothing else lit: small lights seen directly,
    in a mirror and through glass."""
    gltf = gs.Gltf("chrome-candles")
    table = textured(gltf, "noise table", noise_png(), roughness=0.8)
    add_quad(gltf, "table", [(-3, 0, 3), (3, 0, 3), (3, 0, -3), (-3, 0, -3)], (0, 1, 0), table,
             uv_scale=(4, 4))
    small_lamps(gltf, [(1.0, 0.7, 0.35)] * 7,
                [(-1.0, 0.35, 0.3), (-0.6, 0.3, -0.7), (0.0, 0.4, -1.0), (0.7, 0.3, -0.6),
                 (1.1, 0.35, 0.4), (0.4, 0.3, 0.9), (-0.5, 0.3, 0.9)], 0.025, 500.0)
    add_sphere(gltf, "chrome ball", gltf.material("chrome", (0.95, 0.95, 0.95), 1.0, 0.03),
               (0.0, 0.3, 0.0), 0.3)
    add_sphere(gltf, "glass ball", glass(gltf, "glass", (1.0, 1.0, 1.0)), (-0.6, 0.2, 0.1), 0.2)
    add_box(gltf, "gold block", gltf.material("gold", (1.0, 0.78, 0.34), 1.0, 0.2),
            (0.55, 0.2, 0.1), (0.25, 0.4, 0.25), yaw=15.0)
    add_camera(gltf, (0.0, 1.1, 2.6), (0.0, 0.2, 0.0), 42.0, 1.5)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


# ---------------------------------------------------------------------------------------------
# A report-only set (added 2026-12-07, seventeenth session): nine scenes of kinds the corpus lacks,
# never tuned on, measured with `chorus sweep` (docs/evaluation.md, "The fresh set").


def closed_room(gltf, w, d, h, floor, wall):
    """A room of half width w (x), half depth d (z) and height h, every side closed; the floor's
    texture repeats three times."""
    add_quad(gltf, "floor", [(-w, 0, d), (w, 0, d), (w, 0, -d), (-w, 0, -d)], (0, 1, 0), floor,
             uv_scale=(3, 3))
    add_quad(gltf, "ceiling", [(-w, h, -d), (w, h, -d), (w, h, d), (-w, h, d)], (0, -1, 0), wall)
    add_quad(gltf, "back", [(-w, 0, -d), (w, 0, -d), (w, h, -d), (-w, h, -d)], (0, 0, 1), wall)
    add_quad(gltf, "front", [(-w, 0, d), (w, 0, d), (w, h, d), (-w, h, d)], (0, 0, -1), wall)
    add_quad(gltf, "left", [(-w, 0, -d), (-w, 0, d), (-w, h, d), (-w, h, -d)], (1, 0, 0), wall)
    add_quad(gltf, "right", [(w, 0, -d), (w, 0, d), (w, h, d), (w, h, -d)], (-1, 0, 0), wall)


@scene
def corridor(directory):
    """A long corridor lit by a bright window at its far end and two small ceiling lamps:
    the near walls, seen at grazing angles, are lit only by rare paths (the scene that
    showed the guard dropping a sparse tail's light, docs/outliers.md)."""
    gltf = gs.Gltf("corridor")
    wall = gs.lambertian(gltf, "plaster", (0.7, 0.68, 0.62))
    floor = textured(gltf, "planks", planks_png(), roughness=0.35)
    w, h, L = 0.8, 2.2, 12.0
    add_quad(
        gltf,
        "floor",
        [(-w, 0, 1), (w, 0, 1), (w, 0, -L), (-w, 0, -L)],
        (0, 1, 0),
        floor,
        uv_scale=(1, 8),
    )
    add_quad(gltf, "ceiling", [(-w, h, -L), (w, h, -L), (w, h, 1), (-w, h, 1)], (0, -1, 0), wall)
    add_quad(gltf, "left", [(-w, 0, -L), (-w, 0, 1), (-w, h, 1), (-w, h, -L)], (1, 0, 0), wall)
    add_quad(gltf, "right", [(w, 0, -L), (w, 0, 1), (w, h, 1), (w, h, -L)], (-1, 0, 0), wall)
    add_quad(
        gltf,
        "end light",
        [(-w, 0, -L), (w, 0, -L), (w, h, -L), (-w, h, -L)],
        (0, 0, 1),
        emissive(gltf, "window", (1.0, 0.97, 0.9), 20.0),
    )
    for i, z in enumerate((-3.0, -6.5)):
        add_quad(
            gltf,
            "lamp%d" % i,
            [
                (-0.1, h - 0.005, z - 0.1),
                (0.1, h - 0.005, z - 0.1),
                (0.1, h - 0.005, z + 0.1),
                (-0.1, h - 0.005, z + 0.1),
            ],
            (0, -1, 0),
            emissive(gltf, "lamp%d" % i, (1.0, 0.8, 0.5), 40.0),
        )
    add_box(
        gltf,
        "bench",
        gltf.material("steel", (0.7, 0.7, 0.72), 1.0, 0.3),
        (0.5, 0.25, -2.0),
        (0.4, 0.5, 1.2),
    )
    add_camera(gltf, (0.0, 1.5, 0.5), (0.0, 1.0, -6.0), 55.0, 1.5)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


@scene
def attic(directory):
    """An attic lit only through a narrow skylight behind a beam, noise-textured walls and a
    plank floor: nearly every pixel is lit by bounces."""
    gltf = gs.Gltf("attic")
    wall = textured(gltf, "noise wall", noise_png(), roughness=0.9)
    floor = textured(gltf, "planks", planks_png(), roughness=0.5)
    w, dd, h = 1.5, 2.0, 2.2
    add_quad(
        gltf,
        "floor",
        [(-w, 0, dd), (w, 0, dd), (w, 0, -dd), (-w, 0, -dd)],
        (0, 1, 0),
        floor,
        uv_scale=(2, 2),
    )
    # ceiling with a skylight hole: two quads leaving a gap around z in [-0.3, 0.3]
    add_quad(
        gltf, "ceil a", [(-w, h, -dd), (w, h, -dd), (w, h, -0.3), (-w, h, -0.3)], (0, -1, 0), wall
    )
    add_quad(gltf, "ceil b", [(-w, h, 0.3), (w, h, 0.3), (w, h, dd), (-w, h, dd)], (0, -1, 0), wall)
    add_quad(gltf, "back", [(-w, 0, -dd), (w, 0, -dd), (w, h, -dd), (-w, h, -dd)], (0, 0, 1), wall)
    add_quad(gltf, "front", [(-w, 0, dd), (w, 0, dd), (w, h, dd), (-w, h, dd)], (0, 0, -1), wall)
    add_quad(gltf, "left", [(-w, 0, -dd), (-w, 0, dd), (-w, h, dd), (-w, h, -dd)], (1, 0, 0), wall)
    add_quad(gltf, "right", [(w, 0, -dd), (w, 0, dd), (w, h, dd), (w, h, -dd)], (-1, 0, 0), wall)
    add_quad(
        gltf,
        "sky panel",
        [(-w, h + 0.6, -0.3), (w, h + 0.6, -0.3), (w, h + 0.6, 0.3), (-w, h + 0.6, 0.3)],
        (0, -1, 0),
        emissive(gltf, "sky", (0.8, 0.9, 1.0), 30.0),
    )
    add_box(
        gltf,
        "beam",
        gs.lambertian(gltf, "dark wood", (0.3, 0.2, 0.12)),
        (0, h - 0.2, 0),
        (2 * w, 0.25, 0.25),
    )
    add_box(
        gltf,
        "chest",
        gs.lambertian(gltf, "green", (0.2, 0.5, 0.25)),
        (0.6, 0.3, -0.8),
        (0.8, 0.6, 0.5),
        yaw=12,
    )
    add_sphere(
        gltf, "silver", gltf.material("silver", (0.9, 0.9, 0.92), 1.0, 0.15), (-0.5, 0.3, 0.2), 0.3
    )
    add_camera(gltf, (-1.2, 1.4, 1.8), (0.3, 0.7, -0.8), 60.0, 1.5)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


@scene
def bathroom(directory):
    """The Cornell room with a glossy tiled floor, a chrome ball, an enamel tub and a blue
    glass sphere under a ceiling light."""
    gltf = gs.Gltf("bathroom")
    tiles = textured(gltf, "tiles", fine_checker_png(128, 16), roughness=0.1)
    white = cornell_room(gltf, tiles)
    add_quad(
        gltf,
        "light",
        [(-0.4, 1.995, -0.2), (0.4, 1.995, -0.2), (0.4, 1.995, 0.2), (-0.4, 1.995, 0.2)],
        (0, -1, 0),
        emissive(gltf, "lamp", (1.0, 0.95, 0.9), 12.0),
    )
    add_sphere(
        gltf,
        "chrome",
        gltf.material("chrome", (0.95, 0.95, 0.95), 1.0, 0.02),
        (-0.4, 0.3, 0.1),
        0.3,
    )
    add_box(
        gltf,
        "tub",
        gltf.material("enamel", (0.9, 0.9, 0.88), 0.0, 0.2),
        (0.35, 0.25, -0.3),
        (0.6, 0.5, 0.9),
        yaw=-10,
    )
    add_sphere(gltf, "soap", glass(gltf, "blue glass", (0.6, 0.8, 1.0)), (0.2, 0.15, 0.5), 0.15)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


@scene
def garden(directory):
    """Twenty boxes of five materials (plastic, gold, rough green, chrome, glossy blue) on a
    fine checker ground, for an environment map: much geometric detail."""
    gltf = gs.Gltf("garden")
    ground = textured(gltf, "checker", fine_checker_png(128, 4), roughness=0.8)
    add_quad(
        gltf,
        "ground",
        [(-6, 0, 6), (6, 0, 6), (6, 0, -6), (-6, 0, -6)],
        (0, 1, 0),
        ground,
        uv_scale=(6, 6),
    )
    mats = [
        gltf.material("m%d" % i, c, m, r)
        for i, (c, m, r) in enumerate(
            [
                ((0.8, 0.2, 0.2), 0, 0.3),
                ((0.9, 0.8, 0.4), 1, 0.25),
                ((0.2, 0.6, 0.3), 0, 0.8),
                ((0.8, 0.8, 0.85), 1, 0.05),
                ((0.3, 0.3, 0.8), 0, 0.1),
            ]
        )
    ]
    k = 0
    for i in range(5):
        for j in range(4):
            h = 0.2 + 0.15 * ((i * 7 + j * 3) % 5)
            add_box(
                gltf,
                "b%d_%d" % (i, j),
                mats[k % 5],
                (-1.2 + 0.6 * i, h / 2, -1.0 + 0.6 * j),
                (0.3, h, 0.3),
                yaw=(i * 17 + j * 29) % 90,
            )
            k += 1
    add_camera(gltf, (0.0, 1.8, 3.2), (0.0, 0.2, -0.2), 45.0, 1.5)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


@scene
def stage(directory):
    """A spot light on a white ball before a red curtain, a rough gold box and a blue point
    light behind: hard-edged light pools on a dark glossy floor."""
    gltf = gs.Gltf("stage")
    floor = gltf.material("dark floor", (0.05, 0.05, 0.06), 0.0, 0.3)
    add_quad(gltf, "floor", [(-4, 0, 4), (4, 0, 4), (4, 0, -4), (-4, 0, -4)], (0, 1, 0), floor)
    add_quad(
        gltf,
        "curtain",
        [(-4, 0, -1.5), (4, 0, -1.5), (4, 3, -1.5), (-4, 3, -1.5)],
        (0, 0, 1),
        gs.lambertian(gltf, "red curtain", (0.5, 0.05, 0.05)),
    )
    add_sphere(gltf, "ball", gs.lambertian(gltf, "white", (0.8, 0.8, 0.8)), (0.0, 0.5, 0.0), 0.5)
    add_box(
        gltf,
        "box",
        gltf.material("rough gold", (1.0, 0.78, 0.34), 1.0, 0.35),
        (1.1, 0.3, -0.5),
        (0.6, 0.6, 0.6),
        yaw=30,
    )
    gltf.doc["extensions"] = {
        "KHR_lights_punctual": {
            "lights": [
                {
                    "name": "spot",
                    "type": "spot",
                    "color": [1.0, 0.95, 0.85],
                    "intensity": 60.0,
                    "spot": {"innerConeAngle": 0.1, "outerConeAngle": 0.25},
                },
                {"name": "rim", "type": "point", "color": [0.3, 0.5, 1.0], "intensity": 4.0},
            ]
        }
    }
    gltf.extensions.add("KHR_lights_punctual")
    s = [0.5, 3.0, 2.0]
    gltf.node(
        "spot",
        translation=s,
        rotation=gs.look_at_rotation(s, [0, 0.4, 0]),
        extensions={"KHR_lights_punctual": {"light": 0}},
    )
    gltf.node(
        "rim", translation=[-0.8, 1.2, -1.0], extensions={"KHR_lights_punctual": {"light": 1}}
    )
    add_camera(gltf, (0.0, 1.3, 3.5), (0.0, 0.5, 0.0), 40.0, 1.5)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


@scene
def library(directory):
    """A room lit by a window in its side wall, four shelves of books (many small boxes), a
    brass globe and a plank floor."""
    gltf = gs.Gltf("library")
    wall = gs.lambertian(gltf, "cream", (0.8, 0.75, 0.65))
    floor = textured(gltf, "planks", planks_png(), roughness=0.4)
    w, dd, h = 2.0, 2.0, 2.5
    closed_room(gltf, w, dd, h, floor, wall)
    add_quad(
        gltf,
        "window",
        [
            (-w + 0.01, 1.0, -0.6),
            (-w + 0.01, 1.0, 0.6),
            (-w + 0.01, 2.0, 0.6),
            (-w + 0.01, 2.0, -0.6),
        ],
        (1, 0, 0),
        emissive(gltf, "window", (0.9, 0.95, 1.0), 15.0),
    )
    cols = [(0.5, 0.1, 0.1), (0.1, 0.3, 0.5), (0.6, 0.5, 0.2), (0.2, 0.4, 0.2), (0.4, 0.4, 0.4)]
    mats = [gs.lambertian(gltf, "book%d" % i, c) for i, c in enumerate(cols)]
    for shelf in range(4):
        y = 0.3 + 0.5 * shelf
        add_box(
            gltf,
            "shelf%d" % shelf,
            gs.lambertian(gltf, "wood%d" % shelf, (0.35, 0.22, 0.12)),
            (0.5, y - 0.03, -dd + 0.2),
            (2.6, 0.04, 0.35),
        )
        for b in range(14):
            hb = 0.25 + 0.15 * ((b * 5 + shelf * 3) % 4) / 3
            add_box(
                gltf,
                "book%d_%d" % (shelf, b),
                mats[(b + shelf) % 5],
                (-0.7 + 0.18 * b, y + hb / 2, -dd + 0.2),
                (0.12, hb, 0.3),
            )
    add_sphere(
        gltf, "globe", gltf.material("brass", (0.9, 0.7, 0.35), 1.0, 0.2), (1.2, 0.35, 0.6), 0.35
    )
    add_camera(gltf, (-0.5, 1.3, 1.8), (0.6, 0.9, -1.8), 55.0, 1.5)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


@scene
def kitchen(directory):
    """Three spot lights over a black glossy counter and a tiled splash-back, a steel bowl,
    an orange and a wooden board."""
    gltf = gs.Gltf("kitchen")
    counter = gltf.material("black granite", (0.05, 0.05, 0.05), 0.0, 0.15)
    add_quad(gltf, "counter", [(-3, 0, 3), (3, 0, 3), (3, 0, -3), (-3, 0, -3)], (0, 1, 0), counter)
    add_quad(
        gltf,
        "splash",
        [(-3, 0, -1), (3, 0, -1), (3, 2, -1), (-3, 2, -1)],
        (0, 0, 1),
        textured(gltf, "tiles", fine_checker_png(128, 16), roughness=0.2),
        uv_scale=(4, 2),
    )
    add_sphere(
        gltf, "bowl", gltf.material("steel", (0.8, 0.8, 0.8), 1.0, 0.1), (-0.4, 0.25, 0.0), 0.25
    )
    add_sphere(
        gltf, "orange", gs.lambertian(gltf, "orange", (0.9, 0.4, 0.05)), (0.3, 0.15, 0.2), 0.15
    )
    add_box(
        gltf,
        "board",
        textured(gltf, "wood", planks_png(), roughness=0.8),
        (0.5, 0.03, -0.3),
        (0.8, 0.06, 0.5),
        yaw=10,
    )
    gltf.doc["extensions"] = {
        "KHR_lights_punctual": {
            "lights": [
                {
                    "name": "s%d" % i,
                    "type": "spot",
                    "color": [1.0, 0.9, 0.75],
                    "intensity": 25.0,
                    "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5},
                }
                for i in range(3)
            ]
        }
    }
    gltf.extensions.add("KHR_lights_punctual")
    for i, x in enumerate((-1.0, 0.0, 1.0)):
        p = [x, 1.8, 0.0]
        gltf.node(
            "s%d" % i,
            translation=p,
            rotation=gs.look_at_rotation(p, [x * 0.8, 0, -0.2]),
            extensions={"KHR_lights_punctual": {"light": i}},
        )
    add_camera(gltf, (0.0, 1.1, 2.2), (0.0, 0.2, -0.3), 45.0, 1.5)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


@scene
def cellar(directory):
    """A stone cellar lit by one small, very bright lamp hidden behind a pillar, barrels and
    a green glass bottle: indirect light and noise texture everywhere."""
    gltf = gs.Gltf("cellar")
    stone = textured(gltf, "stone", noise_png(), roughness=0.95)
    w, dd, h = 2.0, 2.5, 2.0
    closed_room(gltf, w, dd, h, stone, stone)
    add_box(gltf, "pillar", stone, (0.3, h / 2, -0.8), (0.4, h, 0.4))
    add_sphere(
        gltf, "lamp", emissive(gltf, "lamp", (1.0, 0.7, 0.4), 200.0), (0.45, 1.0, -1.3), 0.05
    )
    for i in range(3):
        add_box(
            gltf,
            "barrel%d" % i,
            gs.lambertian(gltf, "oak%d" % i, (0.4, 0.25, 0.12)),
            (-1.3 + 0.6 * i, 0.35, -2.0),
            (0.5, 0.7, 0.5),
            yaw=15 * i,
        )
    add_sphere(gltf, "bottle", glass(gltf, "green glass", (0.3, 0.8, 0.3)), (-0.6, 0.2, 0.3), 0.2)
    add_camera(gltf, (0.0, 1.2, 2.2), (0.0, 0.7, -1.5), 60.0, 1.5)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)


@scene
def pool(directory):
    """A glass slab of water on a tiled ground, a red plastic and a chrome ball, for an
    environment map."""
    gltf = gs.Gltf("pool")
    add_quad(
        gltf,
        "ground",
        [(-6, 0, 6), (6, 0, 6), (6, 0, -6), (-6, 0, -6)],
        (0, 1, 0),
        textured(gltf, "tiles", fine_checker_png(128, 8), roughness=0.3),
        uv_scale=(8, 8),
    )
    add_box(gltf, "water", glass(gltf, "water", (0.7, 0.9, 1.0)), (0, 0.1, 0), (3.0, 0.2, 2.0))
    add_sphere(
        gltf, "ball", gltf.material("red plastic", (0.8, 0.1, 0.1), 0.0, 0.2), (1.8, 0.3, 0.8), 0.3
    )
    add_sphere(
        gltf,
        "chrome",
        gltf.material("chrome", (0.95, 0.95, 0.95), 1.0, 0.02),
        (-1.9, 0.3, 0.6),
        0.3,
    )
    add_camera(gltf, (0.0, 2.0, 3.5), (0.0, 0.0, 0.0), 45.0, 1.5)
    gs._attach_base_color_textures(gltf)
    gltf.write(directory, embed_buffer=True)

def main():
    if len(sys.argv) != 2:
        sys.stderr.write("usage: generate_corpus_scenes.py OUTPUT_DIR\n")
        return 2
    directory = sys.argv[1]
    os.makedirs(directory, exist_ok=True)
    for name, write in SCENES.items():
        write(directory)
    return 0


if __name__ == "__main__":
    sys.exit(main())
