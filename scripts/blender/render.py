"""Render a plume run (.glb from `apps/feather --gltf`) with Blender's Cycles on the CPU.

Usage (headless, Blender 3.4, e.g. Debian's `blender` package; scripts/blender/blender.sh runs
`blender -b --factory-startup` with the system's Python first on PATH):

    scripts/blender/blender.sh --python scripts/blender/render.py -- RUN.glb \
        [--out PATH] [--frame K|A-B|all] [--size WxH] [--samples N] [--seed S] \
        [--camera ROT_X,ROT_Z]

    --out      a PNG file for one frame (default: RUN.png next to the .glb); for
               several frames a directory (frames go to DIR/frame_KKKKK.png) or a
               pattern holding "{frame}" (e.g. out/wing_{frame:05d}.png)
    --frame    plume frame index (default: the last), a range A-B (inclusive) or "all"
    --size     image size in pixels (default 1200x800)
    --samples  Cycles samples per pixel (default 128)
    --seed     Cycles' sampling seed (default 0)
    --camera   gnuplot's `set view ROT_X, ROT_Z` in degrees (default: the run's camera)

The .glb holds one node per scene object, one primitive per material (named
`vane`, `rachis`, `kinematic` or `material_K`), frame 0 in the mesh and one morph
target per later frame, and the run's camera and frame times in the glTF scene's
extras ("plume"). The importer turns glTF's y up back into the scene's z up, so
Blender's coordinates are the scene's. The camera looks like gnuplot's view
(rot_x about the screen's horizontal axis, rot_z about the vertical z; (0, 0)
looks straight down) and frames the objects' bounding box over the rendered frames.

Prints one line per picture written: path, size, samples, seconds.
"""

import argparse
import json
import math
import struct
import sys
import time
from pathlib import Path

import bpy
import numpy
from mathutils import Euler, Vector

MAX_FPS = 32767  # Blender's limit on scene.render.fps
LENS_MM = 60.0  # a slightly long lens: little perspective distortion
MARGIN = 0.06  # fraction of the picture left free around the objects
REPO = Path(__file__).resolve().parents[2]

# Warm, light feather tones; feather i gets TINTS[(i * 7) % len(TINTS)] so that
# neighbours (consecutive indices) differ.
TINTS = [
    (0.72, 0.58, 0.40),
    (0.42, 0.30, 0.19),
    (0.80, 0.74, 0.62),
    (0.55, 0.40, 0.26),
    (0.66, 0.62, 0.55),
    (0.35, 0.27, 0.21),
    (0.78, 0.64, 0.46),
    (0.50, 0.45, 0.40),
    (0.70, 0.52, 0.34),
    (0.60, 0.55, 0.46),
    (0.46, 0.34, 0.24),
]


def fail(message):
    """Print a one-line error and leave Blender with a non-zero status."""
    print(f"render.py: error: {message}", file=sys.stderr)
    sys.exit(2)


def parse_args():
    """Arguments after Blender's own, i.e. after `--`."""
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="render.py", description=__doc__.split("\n")[0])
    p.add_argument("glb", type=Path, help="the run's .glb (apps/feather --gltf)")
    p.add_argument("--out", help="PNG file, or directory / {frame} pattern for several frames")
    p.add_argument("--frame", default="last", help="plume frame index, A-B or all (default: the last)")
    p.add_argument("--size", default="1200x800", help="WxH in pixels")
    p.add_argument("--samples", type=int, default=128, help="Cycles samples per pixel")
    p.add_argument("--seed", type=int, default=0, help="Cycles' sampling seed")
    p.add_argument("--camera", help="ROT_X,ROT_Z in degrees (gnuplot's set view)")
    a = p.parse_args(argv)
    if not a.glb.is_file():
        fail(f"no such file: {a.glb}")
    try:
        a.size = tuple(int(v) for v in a.size.lower().split("x"))
        assert len(a.size) == 2 and min(a.size) > 0
    except (ValueError, AssertionError):
        fail(f"--size: expected WxH, got {a.size!r}")
    if a.samples < 1:
        fail(f"--samples: expected a positive count, got {a.samples}")
    if a.camera is not None:
        try:
            a.camera = tuple(float(v) for v in a.camera.split(","))
            assert len(a.camera) == 2
        except (ValueError, AssertionError):
            fail(f"--camera: expected ROT_X,ROT_Z, got {a.camera!r}")
    return a


def read_plume_extras(path):
    """The glTF scene's extras["plume"], read from the .glb's JSON chunk."""
    with open(path, "rb") as f:
        magic, _, _ = struct.unpack("<4sII", f.read(12))
        length, kind = struct.unpack("<I4s", f.read(8))
        if magic != b"glTF" or kind != b"JSON":
            fail(f"{path}: not a binary glTF (.glb) file")
        doc = json.loads(f.read(length))
    scene = doc.get("scenes", [{}])[doc.get("scene", 0)]
    plume = scene.get("extras", {}).get("plume")
    if not plume or not plume.get("frame_times"):
        fail(f"{path}: no plume extras (camera, frame_times) in the glTF scene: not written by plume?")
    return plume


def parse_frames(spec, nframes):
    """Frame indices from --frame: K, A-B, all or last."""
    if spec == "all":
        return list(range(nframes))
    if spec == "last":
        return [nframes - 1]
    try:
        lo, _, hi = spec.partition("-")
        frames = list(range(int(lo), int(hi or lo) + 1))
    except ValueError:
        fail(f"--frame: expected K, A-B or all, got {spec!r}")
    if not frames or frames[0] < 0 or frames[-1] >= nframes:
        fail(f"--frame {spec}: out of range, the run has frames 0 to {nframes - 1}")
    return frames


def output_paths(out, glb, frames):
    """The PNG path of each frame."""
    if len(frames) == 1 and (out is None or out.endswith(".png") and "{" not in out):
        return [Path(out) if out else glb.with_suffix(".png")]
    if out is None:
        out = str(glb.with_suffix("")) + "_frames"
    if "{" in out:
        return [Path(out.format(frame=k)) for k in frames]
    return [Path(out) / f"frame_{k:05d}.png" for k in frames]


def frames_per_second(times):
    """The smallest integer fps up to MAX_FPS that puts every frame time on a whole Blender frame
    (keys then sit on frames, as a user scrubbing the timeline expects); 1000 when there is none
    (adaptive or shortened steps): go_to then reaches a frame through a subframe."""
    t = numpy.asarray(times)
    for fps in range(1, MAX_FPS + 1):
        f = t * fps
        if numpy.abs(f - numpy.round(f)).max() < 1e-6 * fps and len(set(numpy.round(f))) == len(t):
            return fps
    return 1000


def import_glb(path, fps):
    """An empty scene at `fps`, then the .glb: the importer keys frame k at round(t_k * fps)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.context.scene.render.fps = fps
    if "bool" not in vars(numpy):  # Blender 3.4's importer still uses numpy.bool (gone in numpy 1.24)
        numpy.bool = bool
    bpy.ops.import_scene.gltf(filepath=str(path))
    meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    if not meshes:
        fail(f"{path}: no meshes")
    return meshes


def smooth_shading(objects):
    """Smooth shading with normals recomputed from the deformed surface.

    The importer stores the file's normals as custom split normals of frame 0, which
    shape keys do not update; they are dropped so that every frame gets its own.
    """
    for o in objects:
        mesh = o.data
        if mesh.has_custom_normals:
            with bpy.context.temp_override(object=o, active_object=o):
                bpy.ops.mesh.customdata_custom_splitnormals_clear()
        mesh.use_auto_smooth = False
        mesh.polygons.foreach_set("use_smooth", [True] * len(mesh.polygons))


def scene_material_names(plume):
    """Material names of the run's scene file, to name `material_K` (older files)."""
    for base in (Path.cwd(), REPO):
        scene = base / plume.get("scene", "")
        if scene.is_file():
            try:
                return [m.get("name") for m in json.loads(scene.read_text()).get("materials", [])]
            except (OSError, ValueError, AttributeError):
                return []
    return []


def material_role(name, scene_names):
    """vane, rachis or kinematic, from the glTF material's name."""
    base = name.split(".")[0]
    if base.startswith("material_") and base[9:].isdigit():
        k = int(base[9:])
        base = scene_names[k] if k < len(scene_names) and scene_names[k] else base
    if base in ("vane", "rachis", "kinematic"):
        return base
    return "vane"


def new_material(name):
    """A node material with an empty tree and its output node."""
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes = m.node_tree.nodes
    nodes.clear()
    return m, nodes, m.node_tree.links, nodes.new("ShaderNodeOutputMaterial")


def tinted_color(nodes, links, strength):
    """The object's colour (set per feather) as a shader input, scaled by `strength`."""
    info = nodes.new("ShaderNodeObjectInfo")
    scale = nodes.new("ShaderNodeVectorMath")
    scale.operation = "SCALE"
    scale.inputs["Scale"].default_value = strength
    links.new(info.outputs["Color"], scale.inputs[0])
    return scale.outputs["Vector"]


def vane_material():
    """A thin, light, slightly translucent feather vane with a soft sheen."""
    m, nodes, links, out = new_material("plume_vane")
    bsdf = nodes.new("ShaderNodeBsdfPrincipled")
    bsdf.inputs["Roughness"].default_value = 0.55
    bsdf.inputs["Specular"].default_value = 0.3
    bsdf.inputs["Sheen"].default_value = 0.6
    bsdf.inputs["Sheen Tint"].default_value = 0.6
    translucent = nodes.new("ShaderNodeBsdfTranslucent")
    mix = nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.25
    links.new(tinted_color(nodes, links, 1.0), bsdf.inputs["Base Color"])
    links.new(tinted_color(nodes, links, 0.9), translucent.inputs["Color"])
    links.new(bsdf.outputs[0], mix.inputs[1])
    links.new(translucent.outputs[0], mix.inputs[2])
    links.new(mix.outputs[0], out.inputs["Surface"])
    return m


def principled_material(name, color, roughness, specular, clearcoat=0.0):
    """An opaque Principled BSDF material."""
    m, nodes, links, out = new_material(name)
    bsdf = nodes.new("ShaderNodeBsdfPrincipled")
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Specular"].default_value = specular
    bsdf.inputs["Clearcoat"].default_value = clearcoat
    links.new(bsdf.outputs[0], out.inputs["Surface"])
    return m


def assign_materials(objects, plume):
    """Replace the imported materials by role, and tint each feather."""
    by_role = {
        "vane": vane_material(),
        "rachis": principled_material("plume_rachis", (0.10, 0.065, 0.04), 0.32, 0.5, 0.2),
        "kinematic": principled_material("plume_kinematic", (0.30, 0.30, 0.31), 0.75, 0.3),
    }
    scene_names = scene_material_names(plume)
    for o in objects:
        slots = o.material_slots
        for slot in slots:
            slot.material = by_role[material_role(slot.material.name, scene_names)] if slot.material else by_role["vane"]
        index = int(o.get("plume_object", 0))
        o.color = (*TINTS[(index * 7) % len(TINTS)], 1.0)


def box_corners(objects, depsgraph):
    """The 8 corners of each evaluated (deformed) object's world bounding box, as an (n, 3) array."""
    corners = []
    for o in objects:
        ev = o.evaluated_get(depsgraph)
        mesh = ev.to_mesh()
        co = numpy.empty(3 * len(mesh.vertices))
        mesh.vertices.foreach_get("co", co)
        ev.to_mesh_clear()
        m = numpy.array(ev.matrix_world)
        co = co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]
        lo, hi = co.min(0), co.max(0)
        corners += [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    return numpy.array(corners)


def check_morph_weights(objects, k):
    """Warn when the shape keys at plume frame k are not target k-1 alone (frame 0: none)."""
    for o in objects:
        keys = o.data.shape_keys
        if not keys:
            continue
        for i, block in enumerate(keys.key_blocks[1:]):
            if abs(block.value - (1.0 if i == k - 1 else 0.0)) > 1e-4:
                print(f"render.py: warning: {o.name}: shape key {block.name} = {block.value:.4f} at frame {k}",
                      file=sys.stderr)
                return


def go_to(scene, times, fps, k):
    """Show plume frame k (at its time exactly: a subframe when it falls between frames)."""
    f = times[k] * fps
    whole = math.floor(f + 1e-6)
    scene.frame_set(whole, subframe=max(0.0, f - whole))


def frame_corners(scene, objects, times, fps, frames):
    """The objects' bounding box corners over the frames."""
    corners = []
    for k in frames:
        go_to(scene, times, fps, k)
        corners.append(box_corners(objects, bpy.context.evaluated_depsgraph_get()))
    return numpy.concatenate(corners)


def add_camera(scene, rot_x, rot_z, coords):
    """A camera with gnuplot's view framing `coords` (an (n, 3) array) with a margin."""
    data = bpy.data.cameras.new("plume_camera")
    data.lens = LENS_MM
    data.sensor_fit = "AUTO"
    cam = bpy.data.objects.new("plume_camera", data)
    scene.collection.objects.link(cam)
    scene.camera = cam
    cam.rotation_euler = Euler((math.radians(rot_x), 0.0, math.radians(rot_z)), "XYZ")
    centre = (coords.min(0) + coords.max(0)) / 2
    grown = centre + (coords - centre) * (1.0 + 2.0 * MARGIN)
    location, _ = cam.camera_fit_coords(bpy.context.evaluated_depsgraph_get(), grown.ravel().tolist())
    cam.location = location
    span = float(numpy.linalg.norm(coords.max(0) - coords.min(0)))
    data.clip_start, data.clip_end = span * 1e-3, span * 1e3
    return cam


def add_sun(scene, name, energy, elevation, azimuth, angle, color=(1.0, 1.0, 1.0)):
    """A sun light shining from `elevation` above the horizon and `azimuth` about z (degrees)."""
    light = bpy.data.lights.new(name, "SUN")
    light.energy = energy
    light.angle = math.radians(angle)
    light.color = color
    obj = bpy.data.objects.new(name, light)
    scene.collection.objects.link(obj)
    # a sun shines along its -z: tilt it (90 - elevation) down from the zenith, then turn it
    obj.rotation_euler = Euler((math.radians(90.0 - elevation), 0.0, math.radians(azimuth)), "XYZ")
    return obj


def add_lights(scene, rot_z):
    """Key from the upper left of the camera, a fill from the right, a rim from behind."""
    view = rot_z  # azimuth of the camera, in the same convention as the suns'
    add_sun(scene, "key", 2.2, 55.0, view - 45.0, 8.0, (1.0, 0.97, 0.92))
    add_sun(scene, "fill", 0.6, 20.0, view + 70.0, 20.0, (0.90, 0.95, 1.0))
    add_sun(scene, "rim", 1.6, 30.0, view + 165.0, 5.0)


def add_ground(scene, lo, hi):
    """A shadow catcher just below the objects: their shadow on the backdrop."""
    size = 20.0 * float(numpy.linalg.norm(hi - lo))
    mesh = bpy.data.meshes.new("plume_ground")
    mesh.from_pydata([(-size, -size, 0), (size, -size, 0), (size, size, 0), (-size, size, 0)], [], [(0, 1, 2, 3)])
    ground = bpy.data.objects.new("plume_ground", mesh)
    ground.location = ((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2] - 0.02 * (hi[2] - lo[2]))
    ground.is_shadow_catcher = True
    scene.collection.objects.link(ground)


def add_world(scene):
    """A light grey sky for lighting; a soft vertical grey gradient behind the objects."""
    world = bpy.data.worlds.new("plume_world")
    scene.world = world
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputWorld")
    sky = nodes.new("ShaderNodeBackground")
    sky.inputs["Color"].default_value = (0.80, 0.82, 0.85, 1.0)
    sky.inputs["Strength"].default_value = 0.3
    coord = nodes.new("ShaderNodeTexCoord")
    split = nodes.new("ShaderNodeSeparateXYZ")
    ramp = nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].color = (0.42, 0.43, 0.45, 1.0)
    ramp.color_ramp.elements[1].color = (0.80, 0.80, 0.81, 1.0)
    backdrop = nodes.new("ShaderNodeBackground")
    path = nodes.new("ShaderNodeLightPath")
    mix = nodes.new("ShaderNodeMixShader")
    links.new(coord.outputs["Window"], split.inputs[0])
    links.new(split.outputs["Y"], ramp.inputs["Fac"])
    links.new(ramp.outputs["Color"], backdrop.inputs["Color"])
    links.new(path.outputs["Is Camera Ray"], mix.inputs["Fac"])
    links.new(sky.outputs[0], mix.inputs[1])
    links.new(backdrop.outputs[0], mix.inputs[2])
    links.new(mix.outputs[0], out.inputs["Surface"])


def setup_cycles(scene, size, samples, seed):
    """Cycles on the CPU, denoised when this build has OpenImageDenoise, Filmic."""
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = samples
    c.seed = seed
    c.use_adaptive_sampling = True
    c.sample_clamp_indirect = 2.0
    c.blur_glossy = 1.0
    c.max_bounces, c.diffuse_bounces, c.glossy_bounces, c.transmission_bounces = 6, 3, 2, 6
    c.adaptive_threshold = 0.02
    import _cycles  # Blender's Cycles module: which denoisers this build has
    c.use_denoising = bool(getattr(_cycles, "with_openimagedenoise", False))
    if c.use_denoising:
        c.denoiser = "OPENIMAGEDENOISE"
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.image_settings.color_depth = "8"
    scene.view_settings.view_transform = "Filmic"
    scene.view_settings.look = "Medium High Contrast"


def render(scene, path):
    """Render the current frame to `path`; print path, size, samples and seconds."""
    path.parent.mkdir(parents=True, exist_ok=True)
    scene.render.filepath = str(path.resolve())
    start = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    seconds = time.perf_counter() - start
    r = scene.render
    print(f"{path}  {r.resolution_x}x{r.resolution_y}  {scene.cycles.samples} samples  {seconds:.1f} s", flush=True)


def main():
    args = parse_args()
    plume = read_plume_extras(args.glb)
    times = plume["frame_times"]
    frames = parse_frames(args.frame, len(times))
    paths = output_paths(args.out, args.glb, frames)
    rot_x, rot_z = args.camera or (plume["camera"]["rot_x"], plume["camera"]["rot_z"])

    fps = frames_per_second(times)
    objects = import_glb(args.glb, fps)
    scene = bpy.context.scene
    smooth_shading(objects)
    assign_materials(objects, plume)
    corners = frame_corners(scene, objects, times, fps, frames)
    add_camera(scene, rot_x, rot_z, corners)
    add_lights(scene, rot_z)
    add_world(scene)
    add_ground(scene, corners.min(0), corners.max(0))
    setup_cycles(scene, args.size, args.samples, args.seed)
    for k, path in zip(frames, paths):
        go_to(scene, times, fps, k)
        check_morph_weights(objects, k)
        render(scene, path)


if __name__ == "__main__":
    main()
