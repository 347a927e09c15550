"""The Python API of plume: homogenisation, traction tests, fits and dynamic scenes.

Each job sends a JSON request to the flat C interface (include/plume/flat.h) and turns its JSON result
into a small dataclass with numpy arrays. Units are SI throughout: lengths in m, moduli and
stresses in Pa, angles in degrees, times in s. Arguments of the wrong type or shape are refused
here (TypeError / ValueError) before anything reaches the library; values the library refuses
(out of range, unknown keys inside a dict) raise :class:`plume.PlumeError` with plume's message.
"""
import ctypes
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Dict, Optional

import numpy as np

from . import _native
from ._native import PlumeError

__all__ = ["version", "openmp_serial", "homogenize", "traction", "fit", "Scene", "Curve", "HomogenizeResult",
           "TractionResult", "FitResult", "PlumeError", "MODULI"]

#: The four orthotropic moduli, in the order plume uses: Pa, Pa, -, Pa.
MODULI = ("E_xx", "E_yy", "nu_xy", "G_xy")


def version():
    """The version of the loaded libplume, e.g. "3.0.0"."""
    return _native.version()


def openmp_serial():
    """Makes OpenMP parallel regions serial in this process (plume_openmp_serial, lib/core/openmp_env.h).

    plume's apps call it first: Debian's CHOLMOD opens 4-thread OpenMP regions per supernode, which
    on a 2-core machine cost about a quarter of a scene's run in waits (README, "Threads"). It
    affects every OpenMP library in the process, so plume never calls it by itself: call it when
    plume is the process's main work. OMP_MAX_ACTIVE_LEVELS or OMP_THREAD_LIMIT in the
    environment wins."""
    _native.lib.plume_openmp_serial()


# --- results --------------------------------------------------------------------------------------

@dataclass
class Curve:
    """A quasi-static curve: nominal strain (-), nominal stress (Pa), the average relative width
    change wbar (-) and the solver iterations at each step, the rest state first."""
    strain: np.ndarray
    stress: np.ndarray
    wbar: np.ndarray
    iterations: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))


@dataclass
class HomogenizeResult:
    """Homogenised moduli of a microstructure layout (plume.homogenize).

    E_xx, E_yy: Young's moduli along and across the barbs (Pa); nu_xy: Poisson ratio (-); G_xy:
    shear modulus (Pa); C: the 3x3 stiffness tensor in Voigt notation (xx, yy, xy; Pa);
    shear_coupling: relative coupling between shear and extension (0 for an orthotropic cell);
    elements, vertices: size of the cell mesh; newton_iterations: total over the load cases;
    seconds: wall time; curves: "uniaxial_x", "uniaxial_y", "shear" -> Curve (empty when
    strain_max was 0); order: element order (2 quadratic, 1 linear); element_edge: the cell's
    target element edge (m); refinement_change: how converged the moduli are, the tensor's largest
    change (relative, energy scale) from the cell meshed with elements twice as large (-1: not
    estimated); moduli_change: the relative change of each modulus; D_long, D_trans, D_coupling,
    D_twist, D_16, D_26: bending moduli (N m, barb frame; energy density 1/2 (D_long k11^2 + D_trans
    k22^2 + 2 D_coupling k11 k22 + 4 D_twist k12^2 + 4 D_16 k11 k12 + 4 D_26 k22 k12), as a scene
    material's "bending"); D: the 3x3 bending tensor in Voigt notation (k11, k22, 2 k12; N m);
    bending_change: how converged the bending moduli are (relative, -1: not estimated); output:
    the moduli file written (homogenize's output, as given), or None; separation: for a layout
    with hooks, the separation law of a barb line (docs/unzipping.md): "strength" (N/m),
    "energy" (J/m^2), "opening" and "capture" (m), "stiffness" (N/m^2), "peak_opening" (m),
    "cell_length" (m),
    "solves", "newton_iterations", and "tensor": the hooked cell's 3x3 small-strain tensor (Pa,
    as C; the vane before any hook lets go, docs/monoclinic-vane.md); None without hooks; raw:
    the library's JSON result.
    """
    E_xx: float
    E_yy: float
    nu_xy: float
    G_xy: float
    C: np.ndarray
    shear_coupling: float
    elements: int
    vertices: int
    newton_iterations: int
    seconds: float
    curves: Dict[str, Curve]
    order: int = 2
    element_edge: float = 0.0
    refinement_change: float = -1.0
    moduli_change: Dict[str, float] = field(default_factory=dict)
    D_long: float = 0.0
    D_trans: float = 0.0
    D_coupling: float = 0.0
    D_twist: float = 0.0
    D_16: float = 0.0
    D_26: float = 0.0
    D: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    bending_change: float = -1.0
    output: Optional[str] = None
    separation: Optional[Dict[str, float]] = None
    raw: dict = field(repr=False, default_factory=dict)

    @property
    def moduli(self):
        """The four moduli as a dict (accepted by traction and fit)."""
        return {k: getattr(self, k) for k in MODULI}


@dataclass
class TractionResult:
    """A traction test (plume.traction): the sample clamped at y = 0 and y = ly, the top grip pulled
    along y in steps.

    strain: nominal strain delta / ly at each converged step (-), the rest state first;
    stress: nominal stress F / (lx thickness) (Pa); wbar: average relative width change (-);
    iterations: solver iterations of each step; initial_slope: stress / strain at a tiny probe
    strain (Pa); converged: every step converged; failed_step: first step that did not, or -1;
    stop_reason: the solver's reason (text); newton_iterations: total; max_violation: largest
    relative violation of the barb constraint; seconds: wall time; elements, vertices: mesh size;
    model, angle: the request's (angle in degrees between the barbs and the pull); micro model:
    refinement_change, how converged the curve is (its largest stress change from the specimen
    meshed with elements twice as large, over the largest stress; -1: not estimated), order and
    element_edge (m); the energy balance (J): work (the grip's), stored_energy,
    dissipated_energy (what hooks letting go gave up) and energy_balance_error ((work - stored -
    dissipated) over the gross work); hooks_released and hooks_reengaged (a layout with hook keys,
    docs/unzipping.md; with split_lines they count the lines' vertex pairs, split_pairs of them);
    peak_stress (Pa: the largest at any equilibrium, sub-steps included); raw: the library's JSON
    result.
    """
    model: str
    angle: float
    strain: np.ndarray
    stress: np.ndarray
    wbar: np.ndarray
    iterations: np.ndarray
    initial_slope: float
    converged: bool
    failed_step: int
    stop_reason: str
    newton_iterations: int
    max_violation: float
    seconds: float
    elements: int
    vertices: int
    refinement_change: float = -1.0
    order: int = 0
    element_edge: float = 0.0
    peak_stress: float = 0.0
    work: float = 0.0
    stored_energy: float = 0.0
    dissipated_energy: float = 0.0
    energy_balance_error: float = 0.0
    hooks_released: int = 0
    hooks_reengaged: int = 0
    split_pairs: int = 0
    raw: dict = field(repr=False, default_factory=dict)


@dataclass
class FitResult:
    """Fitted macroscale moduli (plume.fit): E_xx, E_yy (Pa), nu_xy (-), G_xy (Pa); residual: the
    final misfit between the model and target curves; evaluations: model evaluations; stop: why
    the optimiser stopped (text); seconds: wall time; raw: the library's JSON result."""
    E_xx: float
    E_yy: float
    nu_xy: float
    G_xy: float
    residual: float
    evaluations: int
    stop: str
    seconds: float
    raw: dict = field(repr=False, default_factory=dict)

    @property
    def moduli(self):
        """The four moduli as a dict (accepted by traction and fit)."""
        return {k: getattr(self, k) for k in MODULI}


def _get(result, key, job):
    try:
        return result[key]
    except KeyError:
        raise PlumeError(0, _native.strerror(0),
                         "plume_flat_%s returned no '%s' (library and package out of step?)"
                         % (job, key)) from None


def _array(values, dtype=float):
    return np.asarray(values if values is not None else [], dtype=dtype)


def _counts(values):
    return np.rint(_array(values)).astype(np.int64)


def _curve(d):
    return Curve(strain=_array(d.get("strain")), stress=_array(d.get("stress")),
                 wbar=_array(d.get("wbar")), iterations=_counts(d.get("iterations")))


# --- argument checks ------------------------------------------------------------------------------

def _number(name, x, minimum=None):
    if isinstance(x, bool) or not isinstance(x, (int, float, np.integer, np.floating)):
        raise TypeError("%s must be a number (got %r)" % (name, x))
    x = float(x)
    if not math.isfinite(x):
        raise ValueError("%s must be finite (got %r)" % (name, x))
    if minimum is not None and x < minimum:
        raise ValueError("%s must be >= %g (got %r)" % (name, minimum, x))
    return x


def _integer(name, x, minimum=None):
    if isinstance(x, bool) or not isinstance(x, (int, np.integer)):
        raise TypeError("%s must be an integer (got %r)" % (name, x))
    x = int(x)
    if minimum is not None and x < minimum:
        raise ValueError("%s must be >= %d (got %d)" % (name, minimum, x))
    return x


def _boolean(name, x):
    if not isinstance(x, (bool, np.bool_)):
        raise TypeError("%s must be True or False (got %r)" % (name, x))
    return bool(x)


def _string(name, x):
    if not isinstance(x, str):
        raise TypeError("%s must be a string (got %r)" % (name, x))
    return x


def _mapping(name, x):
    if not isinstance(x, Mapping):
        raise TypeError("%s must be a dict (got %s)" % (name, type(x).__name__))
    return dict(x)


def _path(name, x):
    if not isinstance(x, (str, os.PathLike)):
        raise TypeError("%s must be a path (got %r)" % (name, x))
    return os.fspath(x)


# The macro traction keys of flat.h shared by traction and fit, with their Python-side checks.
_MACRO_OPTIONS = {
    "lx": _number, "ly": _number, "thickness": _number, "kappa": _number, "edge": _number,
    "constraint": _boolean, "mesh": _string, "steps": _integer, "solver": _string,
}
def _strains(name, x):
    return [float(v) for v in _series(name, x)]


def _law(name, x):
    # a homogenize result's separation law: its arrays (the hooked cell's tensor) as lists
    return {k: (np.asarray(v).tolist() if isinstance(v, np.ndarray) else v) for k, v in _mapping(name, x).items()}


def _tensor(name, x):
    a = _series(name, np.ravel(np.asarray(x, dtype=float)))
    if a.size != 9:
        raise ValueError("%s must be the 3x3 plane-stress tensor, 9 numbers (got %d)" % (name, a.size))
    return [float(v) for v in a]


_TRACTION_OPTIONS = dict(_MACRO_OPTIONS, strain_max=_number, convergence=_boolean, path=_strains,
                         peel=_number, top_grip_free=_number, split_lines=_integer, separation=_law,
                         tensor=_tensor, checkpoint=_path, restart=_path, stop_after=_integer)


def _options(job, options, allowed):
    out = {}
    for k, v in options.items():
        if k not in allowed:
            raise TypeError("%s() got an unexpected keyword argument '%s' (options: %s)"
                            % (job, k, ", ".join(sorted(allowed))))
        out[k] = allowed[k](k, v)
    return out


def _moduli(name, m):
    """A dict of moduli from a dict (passed as is: plume checks its keys) or from an object with
    E_xx, E_yy, nu_xy, G_xy attributes (a HomogenizeResult, a FitResult)."""
    if isinstance(m, Mapping):
        return dict(m)
    if all(hasattr(m, k) for k in MODULI):
        return {k: _number("%s.%s" % (name, k), getattr(m, k)) for k in MODULI}
    raise TypeError("%s must be a dict of %s or an object with those attributes (got %s)"
                    % (name, ", ".join(MODULI), type(m).__name__))


def _series(name, x):
    a = np.asarray(x, dtype=float)
    if a.ndim != 1 or a.size == 0:
        raise ValueError("%s must be a non-empty 1-D sequence of numbers (got shape %s)"
                         % (name, a.shape))
    if not np.all(np.isfinite(a)):
        raise ValueError("%s must hold finite numbers" % name)
    return a


def _target(i, t):
    """{"angle", "strain", "stress"} from a dict, an (angle, strain, stress) tuple or an object
    with those attributes (a TractionResult)."""
    name = "targets[%d]" % i
    if isinstance(t, Mapping):
        missing = [k for k in ("angle", "strain", "stress") if k not in t]
        if missing:
            raise ValueError("%s lacks %s" % (name, ", ".join(missing)))
        angle, strain, stress = t["angle"], t["strain"], t["stress"]
    elif isinstance(t, (tuple, list)):
        if len(t) != 3:
            raise ValueError("%s must be (angle, strain, stress) (got %d items)" % (name, len(t)))
        angle, strain, stress = t
    elif all(hasattr(t, k) for k in ("angle", "strain", "stress")):
        angle, strain, stress = t.angle, t.strain, t.stress
    else:
        raise TypeError("%s must be a dict, an (angle, strain, stress) tuple or a traction result "
                        "(got %s)" % (name, type(t).__name__))
    strain, stress = _series(name + " strain", strain), _series(name + " stress", stress)
    if strain.shape != stress.shape:
        raise ValueError("%s: strain and stress differ in length (%d, %d)"
                         % (name, strain.size, stress.size))
    return {"angle": _number(name + " angle", angle), "strain": strain.tolist(),
            "stress": stress.tolist()}


# --- jobs -----------------------------------------------------------------------------------------

def homogenize(layout=None, strain_max=0.05, steps=10, output=None):
    """Homogenised moduli of a microstructure layout (a periodic cell solved under three
    load cases).

    Args:
        layout: dict of layout keys (defaults for those absent): "layout" ("strips" |
            "barbules"), "phi" (barb surface fraction, -), "d_B" (barb spacing, m), "w_B" (barb
            width, m; sets d_B = w_B / phi), "E_b" (barb Young's modulus, Pa), "nu_b", "ratio"
            (barbule over barb modulus, -), "nu_B", "thickness" (m, the reference the moduli in
            Pa are the membrane stiffness over), "thickness_barb", "thickness_barbule" (m, each
            phase's own; default "thickness"), "kappa" (Pa), "order" (1
            linear or 2 quadratic triangles, the default), "e_rel" (element edge over barb width,
            -; 0, the default, chooses it from the thinnest strip), "barbule_width" (m), "barbule_spacing" (m),
            "barbule_angle" (deg), "hook_strength" (N), "hook_opening", "hook_slide",
            "hook_capture" (m): with hooks the result has the barb line's separation law. None:
            the default strips layout (phi 0.16, E_b 2.5e9 Pa).
        strain_max: largest strain of the three nonlinear curves (-); 0 gives the moduli only.
        steps: steps of each curve.
        output: a file (str or path-like; "cell.h5") to write the moduli to, the one apps/homogenize
            -o writes: /moduli with the bending moduli and how converged they are as attributes,
            the cell curves when strain_max > 0 (docs/hdf5-layout.md). A scene material takes its
            membrane and bending from it with {"from_moduli": "cell.h5"} (docs/scene-format.md).
            Its directory is created with its parents; a path that cannot be written is a
            PlumeError naming it, raised before the solve. None: nothing written.

    Returns:
        HomogenizeResult (moduli in Pa, bending moduli in N m; curves with steps + 1 points each,
        the rest state first; output: the file written, or None).
    """
    request = {"strain_max": _number("strain_max", strain_max, 0.0),
               "steps": _integer("steps", steps)}
    if layout is not None:
        request["layout"] = _mapping("layout", layout)
    if output is not None:
        request["output"] = _path("output", output)
    r = _native.call_job("homogenize", request)
    curves = {k: _curve(v) for k, v in (r.get("curves") or {}).items()}
    return HomogenizeResult(
        E_xx=float(_get(r, "E_xx", "homogenize")), E_yy=float(_get(r, "E_yy", "homogenize")),
        nu_xy=float(_get(r, "nu_xy", "homogenize")), G_xy=float(_get(r, "G_xy", "homogenize")),
        C=_array(_get(r, "C", "homogenize")).reshape(3, 3),
        shear_coupling=float(_get(r, "shear_coupling", "homogenize")),
        elements=int(_get(r, "elements", "homogenize")),
        vertices=int(_get(r, "vertices", "homogenize")),
        newton_iterations=int(_get(r, "newton_iterations", "homogenize")),
        seconds=float(_get(r, "seconds", "homogenize")), curves=curves,
        order=int(_get(r, "order", "homogenize")), element_edge=float(_get(r, "element_edge", "homogenize")),
        refinement_change=float(_get(r, "refinement_change", "homogenize")),
        moduli_change={k: float(v) for k, v in (r.get("moduli_change") or {}).items()},
        **{k: float(_get(r, k, "homogenize")) for k in ("D_long", "D_trans", "D_coupling", "D_twist", "D_16", "D_26")},
        D=_array(_get(r, "D", "homogenize")).reshape(3, 3),
        bending_change=float(_get(r, "bending_change", "homogenize")),
        output=_get(r, "output", "homogenize") if output is not None else None,
        separation=({k: (int(v) if k in ("solves", "newton_iterations") else
                         _array(v).reshape(3, 3) if k == "tensor" else float(v))
                     for k, v in r["separation"].items()} if "separation" in r else None), raw=r)


def traction(model="macro", angle=45.0, moduli=None, layout=None, vtk=None, **options):
    """A traction test of a rectangular sample lx x ly, clamped at y = 0 and y = ly and pulled
    along y, its barbs at `angle` degrees from the pull.

    Args:
        model: "macro" (an orthotropic vane with the given moduli, barbs inextensible when
            constraint is true) or "micro" (the resolved microstructure of `layout`).
        angle: barb angle from the pull direction (deg).
        moduli: macro model: a dict with all of "E_xx", "E_yy", "nu_xy", "G_xy" (Pa, -; a
            dict without some of them is a PlumeError naming the missing keys), or a
            homogenize / fit result; None: plume's defaults (1e4, 1, 0, 1).
        layout: micro model: a dict of layout keys (see homogenize); those absent keep plume's
            defaults for a sample, as apps/traction: barbs d_B = 0.086 ly apart, elements
            elements chosen from the thinnest strip (the cell-scale d_B = 1 mm would be far too fine). The
            thickness and kappa are the sample's.
        vtk: a directory (created with its parents if needed, before the solve; a PlumeError
            naming it when it cannot be): the deformed sample at the rest state and at
            every converged step as a ParaView series: vtk/steps.pvd, vtk/step_NNNNN.vtu (and,
            macro model, the barbs as vtk/step_barbs_NNNNN.vtu).
        **options: the request keys of flat.h: lx, ly (m; default 1, 1.3), thickness (m; 1),
            kappa (Pa; 0), constraint (bool; True), mesh ("aligned" | "unaligned"), edge (element
            edge, m; min(lx, ly) / 20), strain_max (-; 0.05), steps (10), solver ("newton" |
            "ipopt" | "linearized"), convergence (micro model: estimate refinement_change by
            running the test again on a mesh twice as coarse; True), path (the strains the grip
            goes to in turn, each leg in `steps` steps: [0.03, 0, 0.03] loads, unloads, reloads),
            peel (0: the top grip pulls straight; 1: it turns about its x = 0 end), top_grip_free
            (0: the top grip holds its whole edge; 0.9: only its last tenth, a barb pulled by its end),
            split_lines (macro model, aligned mesh: that many barb lines spread across the sample
            split and zip again, docs/unzipping.md) with separation (their law: the "separation"
            of a homogenize result of a layout with hooks, or a dict with "strength" N/m,
            "stiffness" N/m^2, "capture" m), tensor (macro model: the membrane's plane-stress
            tensor, 3x3 Pa in the barb frame, in place of the moduli's orthotropic one: a
            homogenize result's C, which couples the normal strains and the shear of a cell of
            inclined barbules; docs/monoclinic-vane.md), checkpoint (an HDF5 file the run's whole
            state is written to after every step), restart (such a file: the run continues after
            its step, bit for bit as the run that never stopped, with the same options) and
            stop_after (the run ends after that step, its checkpoint written; docs/hdf5-layout.md).

    Returns:
        TractionResult (strain -, stress Pa, wbar -, per step, the rest state first).
    """
    request = {"model": _string("model", model), "angle": _number("angle", angle)}
    if moduli is not None:
        request["moduli"] = _moduli("moduli", moduli)
    if layout is not None:
        request["layout"] = _mapping("layout", layout)
    if vtk is not None:
        request["vtk"] = _path("vtk", vtk)
    request.update(_options("traction", options, _TRACTION_OPTIONS))
    r = _native.call_job("traction", request)
    return TractionResult(
        model=model, angle=request["angle"],
        strain=_array(_get(r, "strain", "traction")), stress=_array(_get(r, "stress", "traction")),
        wbar=_array(_get(r, "wbar", "traction")),
        iterations=_counts(_get(r, "iterations", "traction")),
        initial_slope=float(_get(r, "initial_slope", "traction")),
        converged=bool(_get(r, "converged", "traction")),
        failed_step=int(_get(r, "failed_step", "traction")),
        stop_reason=str(_get(r, "stop_reason", "traction")),
        newton_iterations=int(_get(r, "newton_iterations", "traction")),
        max_violation=float(_get(r, "max_violation", "traction")),
        seconds=float(_get(r, "seconds", "traction")),
        elements=int(_get(r, "elements", "traction")),
        vertices=int(_get(r, "vertices", "traction")),
        refinement_change=float(r.get("refinement_change", -1.0)), order=int(r.get("order", 0)),
        element_edge=float(r.get("element_edge", 0.0)),
        peak_stress=float(r.get("peak_stress", 0.0)), work=float(r.get("work", 0.0)),
        stored_energy=float(r.get("stored_energy", 0.0)),
        dissipated_energy=float(r.get("dissipated_energy", 0.0)),
        energy_balance_error=float(r.get("energy_balance_error", 0.0)),
        hooks_released=int(r.get("hooks_released", 0)), hooks_reengaged=int(r.get("hooks_reengaged", 0)),
        split_pairs=int(r.get("split_pairs", 0)), raw=r)


def fit(targets, start, free=("E_yy", "G_xy"), max_eval=300, xtol_rel=1e-6, **options):
    """Fits macroscale moduli so that macro traction tests reproduce target curves.

    Args:
        targets: a list of targets, each an (angle, strain, stress) tuple, a dict with those keys
            or a TractionResult (angle in deg, strain -, stress Pa). Each target is simulated up
            to its largest strain.
        start: starting moduli: a dict of all of "E_xx", "E_yy", "nu_xy", "G_xy" or a homogenize / fit
            result. The moduli not in `free` stay at their start values.
        free: names of the moduli to fit.
        max_eval: most model evaluations.
        xtol_rel: relative tolerance on the moduli.
        **options: the macro traction keys: lx, ly, thickness, kappa, constraint, mesh, edge,
            steps, solver (see traction).

    Returns:
        FitResult (moduli in Pa; residual, evaluations, stop, seconds).
    """
    if isinstance(targets, (Mapping, str)) or not hasattr(targets, "__iter__"):
        raise TypeError("targets must be a list of targets")
    targets = [_target(i, t) for i, t in enumerate(targets)]
    if not targets:
        raise ValueError("targets is empty: fit needs at least one curve")
    if isinstance(free, str):
        free = (free,)
    free = [_string("free[%d]" % i, f) for i, f in enumerate(free)]
    request = {"targets": targets, "start": _moduli("start", start), "free": free,
               "max_eval": _integer("max_eval", max_eval),
               "xtol_rel": _number("xtol_rel", xtol_rel)}
    request.update(_options("fit", options, _MACRO_OPTIONS))
    r = _native.call_job("fit", request)
    return FitResult(
        E_xx=float(_get(r, "E_xx", "fit")), E_yy=float(_get(r, "E_yy", "fit")),
        nu_xy=float(_get(r, "nu_xy", "fit")), G_xy=float(_get(r, "G_xy", "fit")),
        residual=float(_get(r, "residual", "fit")),
        evaluations=int(_get(r, "evaluations", "fit")), stop=str(_get(r, "stop", "fit")),
        seconds=float(_get(r, "seconds", "fit")), raw=r)


# --- scenes ---------------------------------------------------------------------------------------

class Scene:
    """A dynamic scene (the JSON scene format of apps/feather) being stepped in time.

    Use it as a context manager, or call close() (the scene is also freed when garbage
    collected)::

        with plume.Scene("data/shell/strip_scene.json") as s:
            s.step(10)
            print(s.time, s.positions[:, 2].min())

    Using a closed scene raises ValueError.
    """

    def __init__(self, path):
        """Loads and sets up the scene file at `path` (PlumeError naming the file, line and key
        when it is wrong)."""
        self._handle = None
        self.path = _path("path", path)
        handle = ctypes.c_void_p()
        msg = _native.new_msg()
        status = _native.lib.plume_flat_scene_open(os.fsencode(self.path), ctypes.byref(handle),
                                                   msg, _native.MSG_SIZE)
        if status != 0 and handle.value:
            _native.lib.plume_flat_scene_close(ctypes.byref(handle))
        _native.check(status, msg)
        self._handle = handle

    # lifetime
    def close(self):
        """Frees the scene; later calls do nothing."""
        h, self._handle = getattr(self, "_handle", None), None
        if h is not None and h.value:
            _native.lib.plume_flat_scene_close(ctypes.byref(h))

    @property
    def closed(self):
        """True once close() was called."""
        return self._handle is None

    def __enter__(self):
        self._live()
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def __del__(self):
        try:
            self.close()
        except Exception:  # interpreter shutdown: the library may already be gone
            pass

    def __repr__(self):
        if self.closed:
            return "<plume.Scene %r (closed)>" % self.path
        return "<plume.Scene %r nv=%d nt=%d time=%g s>" % (self.path, self.nv, self.nt, self.time)

    def _live(self):
        if self._handle is None:
            raise ValueError("operation on a closed plume.Scene (%s)" % self.path)
        return self._handle

    # stepping and output
    def step(self, n=1):
        """Advances n time steps of the scene's dt (each halved when it fails to converge; n = 0
        only reports).

        Returns the report dict: "steps" (accepted), "time" (s), "converged" (bool; False when a
        step was not accepted and stopped the call: it did not converge even at the smallest
        substep, or with the "linearized" solver it did not advance; the state then stays at the
        last converged substep), "halvings", "newton_iterations", "max_violation", "seconds",
        "stop_reason"; and for a scene with split lines (its "splits" block), "splits": {"links",
        "splits_opened", "splits_closed" (since t = 0), "open_length", "longest_open_length" (m),
        "dissipated_energy" (J)}; and for a dynamic scene "energy": {"work", "kinetic_energy",
        "kinetic_change", "potential_change", "numerical_dissipation", "commit_dissipation" (J, since
        the scene was loaded), "energy_balance_error"} (docs/apps/feather.md, "The energy balance").
        """
        h = self._live()
        n = _integer("n", n, 0)
        if n > 2**31 - 1:
            raise ValueError("n is too large (got %d)" % n)
        out = ctypes.c_void_p()
        msg = _native.new_msg()
        status = _native.lib.plume_flat_scene_step(h, n, ctypes.byref(out), msg, _native.MSG_SIZE)
        report = _native.take_text(out.value)
        _native.check(status, msg)
        report = report or {}
        if "converged" in report:
            report["converged"] = bool(report["converged"])
        return report

    def write_vtk(self, dir):
        """Writes the current state as the next frame of a ParaView series in directory `dir`
        (created with its parents if needed): dir/frames.pvd and dir/frame_NNNNN.vtu. The first call for a
        directory starts the series, later ones append."""
        h = self._live()
        msg = _native.new_msg()
        _native.check(_native.lib.plume_flat_scene_write_vtk(h, os.fsencode(_path("dir", dir)), msg,
                                                             _native.MSG_SIZE), msg)

    def write_frames(self, path):
        """Appends the current state as the next frame of the frames file `path` (HDF5, the
        frames.h5 of apps/feather: time, step, positions, velocities, multipliers). The first call
        for a path creates the file (and its directory; a file there is replaced), later ones
        append. Read it back with plume.read_frames(path), which finds this scene's triangles
        through the scene file it names."""
        h = self._live()
        msg = _native.new_msg()
        _native.check(_native.lib.plume_flat_scene_write_frames(h, os.fsencode(_path("path", path)), msg,
                                                                _native.MSG_SIZE), msg)

    # sizes and state
    @property
    def nv(self):
        """Number of vertices."""
        return int(_native.lib.plume_flat_scene_nv(self._live()))

    @property
    def nt(self):
        """Number of triangles."""
        return int(_native.lib.plume_flat_scene_nt(self._live()))

    @property
    def time(self):
        """Simulated time (s)."""
        return float(_native.lib.plume_flat_scene_time(self._live()))

    def _doubles(self, fn, width):
        h = self._live()
        a = np.empty((int(_native.lib.plume_flat_scene_nv(h)), width), dtype=np.float64)
        fn(h, a.ctypes.data_as(ctypes.POINTER(ctypes.c_double)))
        return a

    @property
    def positions(self):
        """Vertex positions (m), a (nv, 3) copy."""
        return self._doubles(_native.lib.plume_flat_scene_positions, 3)

    @property
    def velocities(self):
        """Vertex velocities (m/s), a (nv, 3) copy."""
        return self._doubles(_native.lib.plume_flat_scene_velocities, 3)

    @property
    def reference(self):
        """Reference (material) coordinates X of the vertices (m), a (nv, 2) copy."""
        return self._doubles(_native.lib.plume_flat_scene_reference, 2)

    @property
    def triangles(self):
        """Triangles as vertex ids, an (nt, 3) int64 copy."""
        h = self._live()
        a = np.empty((int(_native.lib.plume_flat_scene_nt(h)), 3), dtype=np.dtype(ctypes.c_long))
        _native.lib.plume_flat_scene_triangles(h, a.ctypes.data_as(ctypes.POINTER(ctypes.c_long)))
        return a.astype(np.int64, copy=False)


# --- graphics -------------------------------------------------------------------------------------

def export_gltf(frames, path, scene=None, animation="morph", field=None):
    """Writes the frames of a frames file (frames.h5 of apps/feather, or Scene.write_frames) as a
    glTF 2.0 binary file `path` (.glb) for Blender, web viewers and game engines: a node per scene
    object named as in the scene, a primitive per material, vertex normals, metres, y up, the
    frames as an animation at their times (docs/graphics.md).

    `scene`: the scene file the frames were made from (None: the one the frames file names).
    `animation`: "morph" (morph targets of one mesh per object) or "frames" (a mesh per frame
    shown in turn). `field`: a render field (e.g. "mean_curvature", "strain_bb") written per
    vertex as the attribute "_" + its name in upper case, or None.

    Errors: plume.PlumeError naming the file, the scene or the argument."""
    frames = _path("frames", frames)
    path = _path("path", path)
    if animation not in ("morph", "frames"):
        raise ValueError("animation must be 'morph' or 'frames' (got %r)" % (animation,))
    enc = lambda x: None if x is None else os.fsencode(x)
    msg = _native.new_msg()
    _native.check(_native.lib.plume_flat_gltf_export(enc(frames), enc(path),
                                                     enc(None if scene is None else _path("scene", scene)),
                                                     animation.encode(), None if field is None else
                                                     _string("field", field).encode(), msg, _native.MSG_SIZE), msg)
