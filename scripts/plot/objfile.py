"""The one OBJ reader of the plotting scripts: what yarnhom writes (io/obj_write.hpp)."""
import numpy as np


def read_obj(path, default_group="yarn"):
    """Vertices (n x 3), triangles (m x 3, polygons fanned, 0-based) and polylines as
    (group, [0-based indices]) with the group ("g NAME") each was read in."""
    v, f, lines, group = [], [], [], default_group
    with open(path) as fh:
        for line in fh:
            t = line.split()
            if not t:
                continue
            if t[0] == "v":
                v.append([float(x) for x in t[1:4]])
            elif t[0] == "g":
                group = t[1] if len(t) > 1 else default_group
            elif t[0] == "f":
                idx = [int(x.split("/")[0]) for x in t[1:]]
                idx = [k - 1 if k > 0 else len(v) + k for k in idx]  # negative: counted back from the last vertex
                for k in range(1, len(idx) - 1):
                    f.append([idx[0], idx[k], idx[k + 1]])
            elif t[0] == "l":
                lines.append((group, [int(x.split("/")[0]) - 1 for x in t[1:]]))
    return np.array(v), np.array(f, dtype=int).reshape(-1, 3), lines
