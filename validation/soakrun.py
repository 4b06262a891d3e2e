"""Running soak and reading what it writes, for the validation cases (numpy only)."""
import json
import os
import re
import subprocess

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOAK = os.environ.get("SOAK", os.path.join(ROOT, "build", "soak"))

_PLY_TYPES = {"float": "<f4", "double": "<f8", "uint": "<u4", "int": "<i4", "uchar": "u1", "ushort": "<u2"}


def run(scene, out, sets=(), frames=None, threads=2):
    """soak run SCENE -o OUT with the overrides in sets; returns OUT"""
    cmd = [SOAK, "run", scene, "-o", out, "--overwrite", "--quiet", "--threads", str(threads)]
    if frames is not None:
        cmd += ["--frames", str(frames)]
    for s in sets:
        cmd += ["--set", s]
    subprocess.run(cmd, check=True)
    return out


def read_vertices(path):
    """the vertex element of a binary little-endian PLY as a numpy structured array"""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    if "format binary_little_endian 1.0" not in header:
        raise ValueError(f"{path}: expected a binary little-endian PLY")
    fields, count, in_vertex = [], 0, False
    for line in header:
        words = line.split()
        if words[:2] == ["element", "vertex"]:
            count, in_vertex = int(words[2]), True
        elif words and words[0] == "element":
            in_vertex = False
        elif in_vertex and words[:1] == ["property"] and words[1] != "list":
            fields.append((words[2], _PLY_TYPES[words[1]]))
    return np.frombuffer(data, dtype=np.dtype(fields), count=count, offset=end)


def frames(out, prefix="water"):
    """the frame numbers of OUT's PREFIX_NNNN.ply files, in order"""
    pattern = re.compile(prefix + r"_(\d{4})\.ply$")
    return sorted(int(m.group(1)) for m in map(pattern.match, os.listdir(out)) if m)


def stats(out):
    """stats.jsonl of a run as a list of dicts, one per frame"""
    with open(os.path.join(out, "stats.jsonl")) as f:
        return [json.loads(line) for line in f if line.strip()]
