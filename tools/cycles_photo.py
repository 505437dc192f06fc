# cycles_photo.py — one synthetic "photograph" of a glTF room lit by a small spherical lamp, made
# with Blender Cycles by the recipe of shared/photos/cornell-box/README.md ("How they were made"):
# the glTF's own emission removed before the import, the glTF camera kept (vertical FOV, pose),
# every material a Lambertian diffuser of its base colour, one Blender point light (radius 0.04,
# 30 W, invisible to the camera), box pixel filter of 1 pixel, black world, 6 bounces with no
# Russian roulette before them, no clamping, no denoising, no adaptive sampling, CPU.
#
# Needs Blender 3.4 (Debian 12: apt-get install blender; not in tools/setup.sh, nothing else uses it):
#   blender -b -P tools/cycles_photo.py -- SCENE.gltf --lamp X Y Z -o photo.exr \
#       [--spp 1024] [--size 256] [--seed 0] [--power 30] [--radius 0.04] [--threads 2] [--albedo albedo.exr]
#
# The lamp position is in the glTF's world coordinates (Y up); the output is an RGB half-float ZIP
# EXR of linear radiance (the Combined pass), in the units of the glTF's emission.
import argparse
import json
import os
import sys
import tempfile

import bpy
import numpy

# Debian 12's numpy 1.24 dropped the alias that Blender 3.4's glTF importer still uses.
if not hasattr(numpy, "bool"):
    numpy.bool = bool


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="blender -b -P tools/cycles_photo.py --")
    p.add_argument("scene", help="the glTF room")
    p.add_argument("--lamp", nargs=3, type=float, required=True, metavar=("X", "Y", "Z"),
                   help="lamp centre in glTF world coordinates (Y up)")
    p.add_argument("-o", "--output", required=True, help="output EXR")
    p.add_argument("--spp", type=int, default=1024)
    p.add_argument("--size", type=int, default=256, help="width = height in pixels")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--power", type=float, default=30.0, help="Blender point-light power, W")
    p.add_argument("--radius", type=float, default=0.04, help="lamp radius")
    p.add_argument("--bounces", type=int, default=6)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--camera", type=int, default=0, help="the glTF camera")
    p.add_argument("--albedo", help="also write the Diffuse Color pass here")
    return p.parse_args(argv)


def gltf_without_emission(path):
    """A copy of the glTF with every material's emission removed (buffers made absolute)."""
    with open(path) as f:
        gltf = json.load(f)
    folder = os.path.dirname(os.path.abspath(path))
    for m in gltf.get("materials", []):
        m.pop("emissiveFactor", None)
        m.pop("emissiveTexture", None)
        m.get("extensions", {}).pop("KHR_materials_emissive_strength", None)
    for b in gltf.get("buffers", []):
        if "uri" in b and not b["uri"].startswith("data:"):
            b["uri"] = os.path.join(folder, b["uri"])
    for im in gltf.get("images", []):
        if "uri" in im and not im["uri"].startswith("data:"):
            im["uri"] = os.path.join(folder, im["uri"])
    gltf.pop("extensions", None)  # no KHR_lights_punctual: the lamp is the only light
    for node in gltf.get("nodes", []):
        node.get("extensions", {}).pop("KHR_lights_punctual", None)
    for key in ("extensionsUsed", "extensionsRequired"):
        if key in gltf:
            gltf[key] = [e for e in gltf[key] if e != "KHR_lights_punctual"]
    out = tempfile.NamedTemporaryFile("w", suffix=".gltf", delete=False)
    json.dump(gltf, out)
    out.close()
    return out.name


def base_colour(material):
    """The glTF baseColorFactor as the importer put it on the Principled BSDF (linear RGB)."""
    if material.use_nodes:
        for node in material.node_tree.nodes:
            if node.type == "BSDF_PRINCIPLED":
                return tuple(node.inputs["Base Color"].default_value)
    return tuple(material.diffuse_color)


def make_lambertian(material):
    """The material as a Lambertian diffuser of its base colour, or of whatever feeds the base
    colour (a texture, a texture times a factor) where the importer linked one."""
    colour = base_colour(material)
    material.use_nodes = True
    nodes = material.node_tree.nodes
    links = material.node_tree.links
    principled = next((n for n in nodes if n.type == "BSDF_PRINCIPLED"), None)
    source = None
    if principled is not None and principled.inputs["Base Color"].is_linked:
        source = principled.inputs["Base Color"].links[0].from_socket
    for node in [n for n in nodes if n.type in ("OUTPUT_MATERIAL", "BSDF_PRINCIPLED")]:
        nodes.remove(node)
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = colour
    diffuse.inputs["Roughness"].default_value = 0.0  # Lambertian (Oren-Nayar sigma 0)
    if source is not None:
        links.new(source, diffuse.inputs["Color"])
    output = nodes.new("ShaderNodeOutputMaterial")
    links.new(diffuse.outputs["BSDF"], output.inputs["Surface"])


def setup_scene(scene_path, camera_index, power, radius, bounces, threads, spp, seed):
    """The room imported without its emission, Lambertian, with its glTF camera, one point lamp
    (returned, at the origin) and the recipe's render settings."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    stripped = gltf_without_emission(scene_path)
    try:
        bpy.ops.import_scene.gltf(filepath=stripped)
    finally:
        os.unlink(stripped)
    cameras = [o for o in scene.objects if o.type == "CAMERA"]
    if not cameras:
        sys.exit(f"{scene_path}: no camera")
    cameras.sort(key=lambda o: o.name)
    scene.camera = cameras[min(camera_index, len(cameras) - 1)]
    for material in bpy.data.materials:
        make_lambertian(material)
    # Objects without a material: the glTF default (white 1.0) is what the glTF means.
    light = bpy.data.lights.new("lamp", type="POINT")
    light.energy = power
    light.shadow_soft_size = radius
    light.color = (1.0, 1.0, 1.0)
    lamp = bpy.data.objects.new("lamp", light)
    lamp.visible_camera = False
    scene.collection.objects.link(lamp)

    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world

    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = spp
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.seed = seed
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.max_bounces = bounces
    c.diffuse_bounces = bounces
    c.glossy_bounces = bounces
    c.transmission_bounces = bounces
    c.volume_bounces = 0
    c.transparent_max_bounces = bounces
    c.min_light_bounces = bounces  # no Russian roulette before the limit
    c.min_transparent_bounces = bounces
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    c.blur_glossy = 0.0
    scene.render.threads_mode = "FIXED"
    scene.render.threads = threads
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.view_settings.look = "None"

    scene.use_nodes = True
    tree = scene.node_tree
    tree.nodes.clear()
    layers = tree.nodes.new("CompositorNodeRLayers")
    composite = tree.nodes.new("CompositorNodeComposite")
    tree.links.new(layers.outputs["Image"], composite.inputs["Image"])
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_depth = "16"
    settings.exr_codec = "ZIP"
    settings.color_mode = "RGB"
    scene.render.use_file_extension = False
    return scene, lamp


def main():
    a = parse_args()
    scene, lamp = setup_scene(a.scene, a.camera, a.power, a.radius, a.bounces, a.threads, a.spp, a.seed)
    # glTF (x, y, z) with Y up is Blender (x, -z, y) with Z up (the importer's convention).
    x, y, z = a.lamp
    lamp.location = (x, -z, y)
    scene.render.resolution_x = a.size
    scene.render.resolution_y = a.size
    tree = scene.node_tree
    layers = next(n for n in tree.nodes if n.type == "R_LAYERS")
    scene.view_layers[0].use_pass_diffuse_color = bool(a.albedo)
    if a.albedo:
        out = tree.nodes.new("CompositorNodeOutputFile")
        out.base_path = os.path.dirname(os.path.abspath(a.albedo))
        out.format.file_format = "OPEN_EXR"
        out.format.color_depth = "16"
        out.format.exr_codec = "ZIP"
        out.format.color_mode = "RGB"
        out.file_slots[0].path = os.path.basename(a.albedo) + "_"
        tree.links.new(layers.outputs["DiffCol"], out.inputs[0])
    scene.render.filepath = os.path.abspath(a.output)
    bpy.ops.render.render(write_still=True)
    if a.albedo:  # the file output node appends the frame number
        written = os.path.join(os.path.dirname(os.path.abspath(a.albedo)), os.path.basename(a.albedo) + "_0001")
        os.replace(written, os.path.abspath(a.albedo))


if __name__ == "__main__":
    main()
