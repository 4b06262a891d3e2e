# blender_import.py: a soak run's frames as animated objects in Blender (checked with Blender 3.4.1).
#
# In Blender: Text Editor > Text > Open this file, set RUN below, Text > Run Script.
# From a shell:  blender --python scripts/blender_import.py -- out/fig3b
# (the folder after `--` replaces RUN; add -b ... -a before `--` to render the animation headless).
#
# Makes the objects soak_cloth (cloth_NNNN.ply), soak_water (water_NNNN.ply, points) and soak_surface
# (water_surface_NNNN.ply of `soak surface --ply`), turned from soak's y-up to Blender's z-up, with
# every PLY property but x y z and the normals as a point attribute. Blender frame FIRST + f shows soak
# frame f; a frame that has no file of a sequence (e.g. outside the range given to `soak surface
# --frames`) shows that object empty. See docs/blender.md.
import json
import os
import re
import struct
import sys

import bpy

RUN = "/path/to/out/fig3b"   # the output folder of `soak run` (and `soak surface --ply`)
FIRST = 1                    # the Blender frame that shows soak frame 0
SEQUENCES = {"soak_cloth": "cloth", "soak_water": "water", "soak_surface": "water_surface"}

if "--" in sys.argv[:-1]:
    RUN = sys.argv[sys.argv.index("--") + 1]

PLY_TYPES = {"char": "b", "uchar": "B", "short": "h", "ushort": "H", "int": "i", "uint": "I",
             "float": "f", "double": "d", "int8": "b", "uint8": "B", "int16": "h", "uint16": "H",
             "int32": "i", "uint32": "I", "float32": "f", "float64": "d"}
INT_PROPERTIES = ("piece", "pinned", "id")


def read_ply(path):
    """soak's binary little-endian PLY -> {element: {property: values}}; faces as index tuples"""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    elements, at = [], end
    for line in data[:end].decode("ascii").splitlines():
        words = line.split()
        if words[:1] == ["format"] and words[1] != "binary_little_endian":
            raise ValueError(path + ": expected binary_little_endian")
        if words[:1] == ["element"]:
            elements.append((words[1], int(words[2]), []))
        elif words[:1] == ["property"]:
            elements[-1][2].append(words[1:])
    out = {}
    for name, count, props in elements:
        if all(p[0] != "list" for p in props):
            fmt = "<" + "".join(PLY_TYPES[p[0]] for p in props)
            size = struct.calcsize(fmt)
            rows = list(struct.iter_unpack(fmt, data[at:at + size * count]))
            at += size * count
            out[name] = {p[-1]: [r[k] for r in rows] for k, p in enumerate(props)}
        else:  # faces: one list property
            _, ctype, itype, pname = props[0]
            cfmt, ifmt = "<" + PLY_TYPES[ctype], PLY_TYPES[itype]
            lists = []
            for _ in range(count):
                (n,) = struct.unpack_from(cfmt, data, at)
                at += struct.calcsize(cfmt)
                lists.append(struct.unpack_from("<%d%s" % (n, ifmt), data, at))
                at += n * struct.calcsize(ifmt)
            out[name] = {pname: lists}
    return out


def y_up_to_z_up(x, y, z):
    """soak's (x, y, z) in Blender: +90 degrees about x"""
    return (x, -z, y)


def build_mesh(name, ply):
    v = ply["vertex"]
    n = len(v["x"])
    verts = [y_up_to_z_up(v["x"][i], v["y"][i], v["z"][i]) for i in range(n)]
    faces = ply["face"]["vertex_indices"] if "face" in ply else []
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    for poly in me.polygons:
        poly.use_smooth = True   # Blender's own vertex normals; soak's nx ny nz are not read
    if "vx" in v:
        vel = me.attributes.new("velocity", "FLOAT_VECTOR", "POINT")
        flat = [c for i in range(n) for c in y_up_to_z_up(v["vx"][i], v["vy"][i], v["vz"][i])]
        vel.data.foreach_set("vector", flat)
    for key, values in v.items():
        if key in ("x", "y", "z", "nx", "ny", "nz", "vx", "vy", "vz"):
            continue
        kind = "INT" if key in INT_PROPERTIES else "FLOAT"
        me.attributes.new(key, kind, "POINT").data.foreach_set("value", values)
    me.update()
    return me


def frames_written():
    """frames 0 .. framesWritten - 1 of run.json (a run in progress or stopped), None if unknown"""
    try:
        with open(os.path.join(RUN, "run.json")) as f:
            return int(json.load(f)["framesWritten"])
    except (OSError, ValueError, KeyError, TypeError):
        return None


def files(prefix, limit):
    pattern = re.compile(re.escape(prefix) + r"_(\d{4,})\.ply$")
    found = {}
    for name in os.listdir(RUN):
        m = pattern.match(name)
        if m and (limit is None or int(m.group(1)) < limit):
            found[int(m.group(1))] = os.path.join(RUN, name)
    return found


if not os.path.isdir(RUN):
    raise FileNotFoundError("soak output folder not found: %r (set RUN)" % RUN)
LIMIT = frames_written()
FILES = {obj: files(prefix, LIMIT) for obj, prefix in SEQUENCES.items()}


def mesh_of(obj_name, frame):
    """the mesh of a soak frame, read once and kept in bpy.data.meshes; an empty one without a file"""
    path = FILES[obj_name].get(frame)
    name = "%s_%04d" % (obj_name, frame) if path else obj_name + "_none"
    if name not in bpy.data.meshes:
        if path:
            build_mesh(name, read_ply(path))
        else:
            bpy.data.meshes.new(name)
    return bpy.data.meshes[name]


def show_frame(scene, *args):
    for obj_name in SEQUENCES:
        obj = bpy.data.objects.get(obj_name)
        if obj is None:
            continue
        me = mesh_of(obj_name, scene.frame_current - FIRST)
        if obj.data is not me:
            me.materials.clear()   # the materials stay with the object from mesh to mesh
            for mat in obj.data.materials:
                me.materials.append(mat)
            obj.data = me


scene = bpy.context.scene
for obj_name in SEQUENCES:
    if FILES[obj_name] and obj_name not in bpy.data.objects:
        obj = bpy.data.objects.new(obj_name, mesh_of(obj_name, min(FILES[obj_name])))
        scene.collection.objects.link(obj)
bpy.app.handlers.frame_change_pre[:] = [h for h in bpy.app.handlers.frame_change_pre
                                        if h.__name__ != "show_frame"]
bpy.app.handlers.frame_change_pre.append(show_frame)
scene.render.use_lock_interface = True   # the handler changes data while frames render
found = sorted(set(k for paths in FILES.values() for k in paths))
if found:
    scene.frame_start, scene.frame_end = FIRST + found[0], FIRST + found[-1]
    show_frame(scene)
for obj_name, prefix in SEQUENCES.items():
    frames = sorted(FILES[obj_name])
    print("soak: %s: %s" % (obj_name, "%s_NNNN.ply, frames %d..%d (%d files)"
                            % (prefix, frames[0], frames[-1], len(frames)) if frames else "no files"))
if found:
    print("soak: Blender frames %d..%d show soak frames %d..%d of %s"
          % (scene.frame_start, scene.frame_end, found[0], found[-1], RUN))
else:
    print("soak: no cloth_NNNN.ply, water_NNNN.ply or water_surface_NNNN.ply in " + RUN)
