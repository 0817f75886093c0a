"""Imports Sylva `.glb` files into Blender headless and prints what Blender made of them.

Usage (Blender 3.4 or later; Debian's `blender` package is 3.4.1):

    blender -b --factory-startup --python tools/blender-check/import_check.py -- \
        [--render OUT.png] FILE.glb [FILE.glb ...]

For each file: the extensions it uses and requires (from its JSON chunk), the triangles the
file draws in its default scene (a mesh's triangles times the instances of its node, from
`EXT_mesh_gpu_instancing` when present), and, after `bpy.ops.import_scene.gltf`, the objects,
meshes and triangles of the imported scene as Blender evaluates it (instances included). A file
Blender refuses prints `REFUSED` and the importer's error. With `--render`, the last file's
scene is rendered (Workbench, looking at the tree from the side) into OUT.png.

Exit status 1 when a file is refused or imports fewer triangles than it draws.
"""

import json
import math
import struct
import sys

import bpy
import mathutils
import numpy

# Debian's Blender 3.4.1 runs on the system's NumPy (1.24 on Debian 12), which dropped the
# `np.bool` alias that the 3.4 glTF importer still uses; give it back before importing.
if "bool" not in numpy.__dict__:
    numpy.bool = bool

INSTANCING = "EXT_mesh_gpu_instancing"


def glb_json(path):
    with open(path, "rb") as f:
        data = f.read()
    magic, _version, _length = struct.unpack_from("<III", data, 0)
    if magic != 0x46546C67:
        raise ValueError(f"{path}: not a binary glTF (magic {magic:#x})")
    chunk_length, chunk_type = struct.unpack_from("<II", data, 12)
    if chunk_type != 0x4E4F534A:
        raise ValueError(f"{path}: first chunk is not JSON")
    return json.loads(data[20 : 20 + chunk_length])


def file_triangles(doc):
    """Triangles the default scene of `doc` draws (as a reader honouring instancing does)."""
    accessors = doc.get("accessors", [])
    meshes = doc.get("meshes", [])
    nodes = doc.get("nodes", [])

    def mesh_triangles(mesh):
        total = 0
        for prim in meshes[mesh]["primitives"]:
            if prim.get("mode", 4) != 4:
                continue
            if "indices" in prim:
                total += accessors[prim["indices"]]["count"] // 3
            else:
                total += accessors[prim["attributes"]["POSITION"]]["count"] // 3
        return total

    def walk(node):
        n = nodes[node]
        total = 0
        if "mesh" in n:
            instances = 1
            ext = n.get("extensions", {}).get(INSTANCING)
            if ext:
                instances = accessors[next(iter(ext["attributes"].values()))]["count"]
            total += mesh_triangles(n["mesh"]) * instances
        for child in n.get("children", []):
            total += walk(child)
        return total

    scene = doc.get("scenes", [])[doc.get("scene", 0)]
    return sum(walk(node) for node in scene.get("nodes", []))


def clear_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def scene_figures():
    """Objects, meshes and evaluated triangles (instances included) of the current scene."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    triangles = 0
    for inst in depsgraph.object_instances:
        obj = inst.object
        if obj.type != "MESH":
            continue
        mesh = obj.data
        mesh.calc_loop_triangles()
        triangles += len(mesh.loop_triangles)
    objects = len(bpy.context.scene.objects)
    meshes = sum(1 for o in bpy.context.scene.objects if o.type == "MESH")
    return objects, meshes, triangles


def render(path):
    scene = bpy.context.scene
    lo = mathutils.Vector((math.inf,) * 3)
    hi = mathutils.Vector((-math.inf,) * 3)
    for obj in scene.objects:
        if obj.type != "MESH":
            continue
        for corner in obj.bound_box:
            p = obj.matrix_world @ mathutils.Vector(corner)
            lo = mathutils.Vector(map(min, lo, p))
            hi = mathutils.Vector(map(max, hi, p))
    center = (lo + hi) / 2
    size = max(hi - lo)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    scene.collection.objects.link(camera)
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = size * 1.1
    # Blender is Z up: the importer turns glTF's +Y up into +Z. Look along +Y (glTF −Z).
    camera.location = (center.x, lo.y - 2 * size, center.z)
    camera.rotation_euler = (math.pi / 2, 0, 0)
    scene.camera = camera
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    scene.collection.objects.link(sun)
    sun.rotation_euler = (0.8, 0.2, 0.5)
    if scene.world is None:
        scene.world = bpy.data.worlds.new("world")
    scene.world.color = (0.8, 0.85, 0.9)
    scene.render.engine = "BLENDER_WORKBENCH"
    shading = scene.display.shading
    shading.light = "STUDIO"
    shading.color_type = "TEXTURE"
    scene.render.resolution_x = 640
    scene.render.resolution_y = 800
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)


def main(argv):
    render_path = None
    files = []
    it = iter(argv)
    for arg in it:
        if arg == "--render":
            render_path = next(it)
        else:
            files.append(arg)
    if not files:
        print("usage: blender -b --python import_check.py -- [--render OUT.png] FILE.glb ...")
        return 2
    print(f"Blender {bpy.app.version_string}")
    print(
        f"{'file':<28} {'file tris':>10} {'objects':>8} {'meshes':>7} {'blender tris':>12}"
        "  extensions (required)"
    )
    failed = False
    for path in files:
        doc = glb_json(path)
        used = doc.get("extensionsUsed", [])
        required = doc.get("extensionsRequired", [])
        expected = file_triangles(doc)
        name = path.rsplit("/", 1)[-1]
        clear_scene()
        try:
            result = bpy.ops.import_scene.gltf(filepath=path)
        except Exception as e:  # the importer raises on files it refuses
            print(f"{name:<28} REFUSED: {e}")
            failed = True
            continue
        if "FINISHED" not in result:
            print(f"{name:<28} REFUSED: {result}")
            failed = True
            continue
        objects, meshes, triangles = scene_figures()
        exts = ", ".join(e + (" (required)" if e in required else "") for e in used)
        print(f"{name:<28} {expected:>10} {objects:>8} {meshes:>7} {triangles:>12}  {exts}")
        if triangles < expected:
            print(f"{name:<28} DROPS {expected - triangles} of {expected} triangles")
            failed = True
    if render_path:
        render(render_path)
        print(f"rendered {files[-1]} into {render_path}")
    return 1 if failed else 0


if __name__ == "__main__":
    args = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else []
    sys.exit(main(args))
