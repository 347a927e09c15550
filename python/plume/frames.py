"""Reading a dynamic run back: the frames file (frames.h5) that apps/feather and Scene.write_frames
write, into numpy arrays (plume.read_frames).

The file is read with h5py (docs/hdf5-layout.md, "Frames file"), frame by frame in the order of
their numbers, whatever order the file lists its groups in (files written before the group names
were zero-padded list "10" before "2"). Only the committed frames (below /frames' count) are read.
"""
import os
from dataclasses import dataclass, field
from typing import Dict, Optional

import numpy as np

__all__ = ["Frames", "read_frames"]

#: Digits of a frame group's name (lib/io/frames.c): "0000000", "0000001", ...
NAME_WIDTH = 7

#: The per-frame measures of the steps since the previous frame (docs/hdf5-layout.md), when the
#: writer recorded them (apps/feather does; Scene.write_frames does not).
MEASURES = ("newton_iterations", "steps_halved", "seconds", "contact_pairs", "min_distance", "intersecting_pairs")


@dataclass
class Frames:
    """A dynamic run read back from its frames file (plume.read_frames). Units are SI.

    Attributes:
        path: the frames file.
        scene: the scene file the run was made from (as the writer recorded it).
        dt: the run's time step (s).
        times: (frames,) time of each frame (s).
        steps: (frames,) int64, time steps taken since t = 0 at each frame.
        positions: (frames, nv, 3) vertex positions (m).
        velocities: (frames, nv, 3) vertex velocities (m/s).
        multipliers: (frames, ncons) multipliers of the inextensible barb edges' constraints
            (N/m; an edge's tension is 2 |lambda| L), of the step that produced each frame.
        triangles: (nt, 3) int64 vertex ids of the scene's mesh (the frames file holds no mesh:
            they come from the scene, see read_frames), or None when read with scene=False.
        measures: name -> (frames,) array of the steps since the previous frame (newton_iterations,
            steps_halved, seconds, contact_pairs, min_distance, intersecting_pairs; -1 for the
            contact ones without contact); NaN for a frame written without them; empty when no
            frame has them.
    """
    path: str
    scene: str
    dt: float
    times: np.ndarray
    steps: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    multipliers: np.ndarray
    triangles: Optional[np.ndarray]
    measures: Dict[str, np.ndarray] = field(default_factory=dict)

    def __len__(self):
        return len(self.times)

    @property
    def nv(self):
        """Number of vertices."""
        return self.positions.shape[1]

    def __repr__(self):
        return "<plume.Frames %r: %d frames, nv=%d, t = %g .. %g s>" % (
            self.path, len(self), self.nv, self.times[0] if len(self) else 0.0,
            self.times[-1] if len(self) else 0.0)


def _frame_group(g, k, path):
    """The group of frame k: its padded name, else the decimal one of older files."""
    padded, plain = "%0*d" % (NAME_WIDTH, k), "%d" % k
    for name in (padded, plain):
        if name in g:
            return g[name], name
    raise ValueError("frames file '%s': /frames/%s is missing (the file's count says %d frames)"
                     % (path, padded, g.attrs["count"]))


def _read_values(fg, name, n, where, path):
    if name not in fg:
        raise ValueError("frames file '%s': /frames/%s/%s is missing" % (path, where, name))
    ds = fg[name]
    if ds.size != n:
        raise ValueError("frames file '%s': /frames/%s/%s has %d values (expected %d)"
                         % (path, where, name, ds.size, n))
    return ds[()].reshape(-1) if n else np.zeros(0)


def _scene_triangles(path, scene, recorded, nv):
    """The triangles of the scene that made the run: a plume.Scene, a scene file, or (None) the
    file the frames file names, found as given, else beside the frames file."""
    from .api import Scene
    if isinstance(scene, Scene):
        tri, snv, where = scene.triangles, scene.nv, scene.path
    else:
        if scene is None:
            tried = [recorded] if os.path.isabs(recorded) else [
                os.path.abspath(recorded), os.path.join(os.path.dirname(os.path.abspath(path)), recorded)]
            found = [p for p in tried if recorded and os.path.isfile(p)]
            if not found:
                raise FileNotFoundError(
                    "frames file '%s': its /frames attribute scene names '%s', which is not at %s; the "
                    "triangles come from the scene: pass scene= (a plume.Scene or the scene file), or "
                    "scene=False to read without them" % (path, recorded, " nor ".join(tried) or "any path"))
            scene = found[0]
        with Scene(scene) as s:
            tri, snv, where = s.triangles, s.nv, s.path
    if snv != nv:
        raise ValueError("frames file '%s' holds %d vertices, but the scene %s has %d: not the scene of this run"
                         % (path, nv, where, snv))
    return tri


def read_frames(path, scene=None):
    """Reads the frames file at `path` (frames.h5 of apps/feather or Scene.write_frames) into a
    :class:`Frames`: times, positions shaped (frames, nv, 3), velocities, multipliers, the measures
    and the triangles.

    The frames file holds no mesh, so the triangles come from the scene: `scene` may be a
    plume.Scene or a scene file; None (the default) loads the scene file the frames file names
    (its /frames attribute scene, as given or relative to the frames file's directory); False
    reads without triangles (Frames.triangles is None).

    Errors: OSError when the file cannot be opened; ValueError naming the file and the missing or
    malformed group, dataset or attribute; FileNotFoundError when the scene is not found;
    plume.PlumeError from loading the scene.
    """
    import h5py  # only here: the rest of plume needs no h5py

    path = os.fspath(path)
    try:
        f = h5py.File(path, "r")
    except OSError as e:
        raise OSError("frames file '%s': cannot open (%s)" % (path, e)) from None
    with f:
        if "frames" not in f or not isinstance(f["frames"], h5py.Group):
            raise ValueError("frames file '%s': has no /frames group (not a plume frames file)" % path)
        g = f["frames"]
        for a in ("count", "nv", "ncons", "dt"):
            if a not in g.attrs:
                raise ValueError("frames file '%s': /frames lacks its attribute %s" % (path, a))
        count, nv, ncons = int(g.attrs["count"]), int(g.attrs["nv"]), int(g.attrs["ncons"])
        dt = float(g.attrs["dt"])
        if count < 0 or nv < 1 or ncons < 0:
            raise ValueError("frames file '%s': /frames has count %d, nv %d, ncons %d (expected count >= 0, "
                             "nv >= 1, ncons >= 0)" % (path, count, nv, ncons))
        recorded = g.attrs.get("scene", "")
        if isinstance(recorded, bytes):
            recorded = recorded.decode("utf-8", "replace")
        times = np.empty(count)
        steps = np.empty(count, dtype=np.int64)
        x = np.empty((count, nv, 3))
        v = np.empty((count, nv, 3))
        lam = np.empty((count, ncons))
        measures = {m: np.full(count, np.nan) for m in MEASURES}
        any_measures = False
        for k in range(count):
            fg, name = _frame_group(g, k, path)
            x[k] = _read_values(fg, "x", 3 * nv, name, path).reshape(nv, 3)
            v[k] = _read_values(fg, "v", 3 * nv, name, path).reshape(nv, 3)
            lam[k] = _read_values(fg, "lambda", ncons, name, path)
            for a in ("t", "step"):
                if a not in fg.attrs:
                    raise ValueError("frames file '%s': /frames/%s lacks its attribute %s" % (path, name, a))
            times[k] = float(fg.attrs["t"])
            steps[k] = int(fg.attrs["step"])
            for m in MEASURES:
                if m in fg.attrs:
                    measures[m][k] = float(fg.attrs[m])
                    any_measures = True
    triangles = None if scene is False else _scene_triangles(path, scene, recorded, nv)
    return Frames(path=path, scene=recorded, dt=dt, times=times, steps=steps, positions=x, velocities=v,
                  multipliers=lam, triangles=triangles, measures=measures if any_measures else {})
