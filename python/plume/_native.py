"""Finding and loading libplume, and the ctypes declarations of its flat C interface (drivers/flat.h).

Everything that touches ctypes lives here; plume.api builds the Python-level API on top of it.

The library is looked for, in this order:

1. the environment variable ``PLUME_LIBRARY`` (a path to the shared library). When it is set it is
   the only candidate: an explicit choice that fails to load is an error, not a silent fallback to
   some other installed copy;
2. ``pkg-config --variable=libdir plume`` (when pkg-config is installed and knows plume):
   ``<libdir>/libplume.so.0``, else ``<libdir>/libplume.so``;
3. the source tree this package sits in, ``<package dir>/../../build/libplume.so`` (use straight
   from a checkout after ``make``);
4. ``ctypes.util.find_library("plume")`` (the dynamic loader's search path).

A candidate that loads but lacks the flat interface (an older plume) is skipped. If none loads,
importing plume raises :class:`LibraryNotFoundError` (an ImportError) listing what was tried.
"""
import ctypes
import ctypes.util
import json
import os
import shutil
import subprocess
from pathlib import Path

#: Size of the message buffers handed to the C functions (bytes, NUL included).
MSG_SIZE = 4096


class LibraryNotFoundError(ImportError):
    """libplume could not be found or loaded; the message lists every candidate tried."""

    __module__ = "plume"


class PlumeError(Exception):
    """An error reported by the plume library.

    Attributes:
        status: the plume_status code (a negative int, see lib/core/status.h).
        status_name: plume_strerror(status), e.g. "invalid input".
        message: plume's own message (naming the file, line, key or parameter); also str(error).
    """

    def __init__(self, status, status_name, message):
        self.status = int(status)
        self.status_name = status_name
        self.message = message or status_name
        super().__init__(self.message)

    __module__ = "plume"  # shown as plume.PlumeError in tracebacks

    def __reduce__(self):
        return (type(self), (self.status, self.status_name, self.message))


# --- finding the library ----------------------------------------------------------------------

def _pkg_config_candidates():
    """Paths under pkg-config's libdir for plume, or [] (with a note) when it does not know plume."""
    exe = shutil.which("pkg-config")
    if exe is None:
        return [], "pkg-config: not installed"
    try:
        out = subprocess.run([exe, "--variable=libdir", "plume"], capture_output=True, text=True,
                             timeout=10)
    except (OSError, subprocess.SubprocessError) as e:
        return [], "pkg-config: %s" % e
    libdir = out.stdout.strip()
    if out.returncode != 0 or not libdir:
        return [], "pkg-config: does not know plume"
    versioned = os.path.join(libdir, "libplume.so.0")
    return [versioned if os.path.exists(versioned) else os.path.join(libdir, "libplume.so")], None


def _candidates():
    """(candidates, notes, exclusive): the library paths/names to try in order, notes on sources
    that gave none, and whether the first candidate was chosen explicitly (PLUME_LIBRARY)."""
    env = os.environ.get("PLUME_LIBRARY")
    if env:
        return [env], [], True
    cands, notes = [], []
    pc, note = _pkg_config_candidates()
    cands += pc
    if note:
        notes.append(note)
    tree = Path(__file__).resolve().parent.parent.parent / "build" / "libplume.so"
    if tree.exists():
        cands.append(str(tree))
    else:
        notes.append("source tree: no %s" % tree)
    found = ctypes.util.find_library("plume")
    if found:
        cands.append(found)
    else:
        notes.append('ctypes.util.find_library("plume"): not found')
    return cands, notes, False


def _load():
    """The first candidate that loads and has the flat interface: (CDLL, path)."""
    cands, notes, exclusive = _candidates()
    tried = []
    for c in cands:
        try:
            lib = ctypes.CDLL(c)
        except OSError as e:
            tried.append("%s: %s" % (c, e))
            continue
        if not hasattr(lib, "plume_flat_scene_open"):
            tried.append("%s: loads but has no plume_flat_* functions (plume older than 0.2?)" % c)
            continue
        return lib, c
    lines = ["cannot load the plume shared library (libplume.so)."]
    if exclusive:
        lines.append("PLUME_LIBRARY is set, so it was the only candidate:")
    else:
        lines.append("Tried:")
    lines += ["  - " + t for t in tried + notes]
    lines.append("Set PLUME_LIBRARY=/path/to/libplume.so, or run `make install` (and check that "
                 "pkg-config or the dynamic loader finds it).")
    raise LibraryNotFoundError("\n".join(lines))


lib, LIBRARY_PATH = _load()

# --- declarations (drivers/flat.h, lib/core/status.h, lib/core/version.h) ---------------------------------

_c_int, _c_long, _c_double, _c_char_p, _c_void_p = (ctypes.c_int, ctypes.c_long, ctypes.c_double,
                                                   ctypes.c_char_p, ctypes.c_void_p)
_msg_t = ctypes.POINTER(ctypes.c_char)        # char *msg (a writable buffer)
_text_out_t = ctypes.POINTER(ctypes.c_void_p)  # char **result (kept raw, to be freed)
_dbl_p = ctypes.POINTER(ctypes.c_double)
_long_p = ctypes.POINTER(ctypes.c_long)


def _declare(name, restype, *argtypes):
    f = getattr(lib, name)
    f.restype = restype
    f.argtypes = list(argtypes)
    return f


_declare("plume_strerror", _c_char_p, _c_int)
_declare("plume_openmp_serial", None)
_declare("plume_version", _c_char_p)
for _job in ("homogenize", "traction", "fit"):
    _declare("plume_flat_" + _job, _c_int, _c_char_p, _text_out_t, _msg_t, _c_long)
_declare("plume_flat_free", None, _c_void_p)
_declare("plume_flat_scene_open", _c_int, _c_char_p, ctypes.POINTER(_c_void_p), _msg_t, _c_long)
_declare("plume_flat_scene_close", None, ctypes.POINTER(_c_void_p))
_declare("plume_flat_scene_step", _c_int, _c_void_p, _c_int, _text_out_t, _msg_t, _c_long)
_declare("plume_flat_scene_nv", _c_long, _c_void_p)
_declare("plume_flat_scene_nt", _c_long, _c_void_p)
_declare("plume_flat_scene_time", _c_double, _c_void_p)
for _what in ("positions", "velocities", "reference"):
    _declare("plume_flat_scene_" + _what, None, _c_void_p, _dbl_p)
_declare("plume_flat_scene_triangles", None, _c_void_p, _long_p)
_declare("plume_flat_scene_write_vtk", _c_int, _c_void_p, _c_char_p, _msg_t, _c_long)


# --- helpers ------------------------------------------------------------------------------------

def strerror(status):
    """plume_strerror(status): the short name of a status code."""
    s = lib.plume_strerror(int(status))
    return s.decode("utf-8", "replace") if s else "status %d" % status


def version():
    """plume_version(): the library's version string, e.g. "1.0.0"."""
    return lib.plume_version().decode()


def new_msg():
    """A zeroed message buffer of MSG_SIZE bytes."""
    return ctypes.create_string_buffer(MSG_SIZE)


def check(status, msg):
    """Raises PlumeError for a non-zero status, with the message plume wrote into msg."""
    if status != 0:
        text = msg.value.decode("utf-8", "replace") if msg is not None else ""
        raise PlumeError(status, strerror(status), text)


def take_text(ptr):
    """The JSON text at a char * the library returned, parsed; the text is freed (plume_flat_free)."""
    if not ptr:
        return None
    try:
        return json.loads(ctypes.string_at(ptr).decode("utf-8"))
    finally:
        lib.plume_flat_free(ptr)


def _json_default(o):
    """json.dumps fallback: numpy scalars and arrays, os.PathLike (paths)."""
    if hasattr(o, "tolist"):      # numpy arrays and scalars
        return o.tolist()
    if isinstance(o, os.PathLike):
        return os.fspath(o)
    raise TypeError("cannot pass a %s to plume (JSON numbers, strings, booleans, lists and "
                    "dicts only)" % type(o).__name__)


def encode_request(request):
    """The request as JSON bytes; non-finite numbers are a ValueError (JSON has none)."""
    try:
        return json.dumps(request, default=_json_default, allow_nan=False).encode("utf-8")
    except ValueError as e:
        raise ValueError("plume requests must hold finite numbers only (%s)" % e) from None


def call_job(job, request):
    """Runs plume_flat_<job> ("homogenize", "traction" or "fit") on a request dict and returns the
    result dict. Raises PlumeError on failure."""
    fn = getattr(lib, "plume_flat_" + job)
    req = encode_request(request)
    out = ctypes.c_void_p()
    msg = new_msg()
    status = fn(req, ctypes.byref(out), msg, MSG_SIZE)
    result = take_text(out.value)  # freed even on failure, should the library have set it
    check(status, msg)
    if result is None:
        raise PlumeError(0, strerror(0), "plume_flat_%s succeeded but returned no result" % job)
    return result

