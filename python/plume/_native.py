"""Finding and loading libplume, and the ctypes declarations of its flat C interface (include/plume/flat.h).

Everything that touches ctypes lives here; plume.api builds the Python-level API on top of it.

The library is looked for, in this order:

1. the environment variable ``PLUME_LIBRARY`` (a path to the shared library). When it is set it is
   the only candidate: an explicit choice that fails to load is an error, not a silent fallback to
   some other installed copy;
2. the path recorded when the package was installed (``pip install``: setup.py writes
   plume/_install.py with what PLUME_LIBRARY, pkg-config or the source tree gave then), so that an
   installed package needs no environment variable;
3. ``pkg-config --variable=libdir plume`` (when pkg-config is installed and knows plume): the
   library named by its soname in that libdir (plume._locate);
4. the source tree this package sits in, ``<package dir>/../../build/libplume.so`` (use straight
   from a checkout after ``make``);
5. ``ctypes.util.find_library("plume")`` (the dynamic loader's search path).

A candidate that loads but lacks the flat interface (an older plume) is skipped. If none loads,
importing plume raises :class:`LibraryNotFoundError` (an ImportError) listing what was tried.
"""
import ctypes
import ctypes.util
import json
import os

from . import _locate

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

def _recorded():
    """(path, note): the library recorded at install (plume/_install.py), or (None, why not)."""
    try:
        from . import _install
    except ImportError:
        return None, "recorded at install: nothing (not an installed copy of the package)"
    if not _install.LIBRARY:
        return None, "recorded at install: nothing was found then (%s)" % "; ".join(_install.NOTES)
    return _install.LIBRARY, None


def _sources():
    """The search after PLUME_LIBRARY, in order: functions giving (path, note), called only when
    the ones before gave nothing that loads (pkg-config is a subprocess)."""
    here = os.path.dirname(os.path.abspath(__file__))
    yield _recorded
    yield _locate.pkg_config
    yield lambda: _locate.source_tree(here)

    def loader():
        found = ctypes.util.find_library("plume")
        return (found, None) if found else (None, 'ctypes.util.find_library("plume"): not found')
    yield loader


def _load():
    """The first candidate that loads and has the flat interface: (CDLL, path)."""
    env = os.environ.get("PLUME_LIBRARY")
    tried = []
    for source in ([lambda: (env, None)] if env else _sources()):
        path, note = source()
        if path is None:
            tried.append(note)
            continue
        why = _locate.check(path)
        if why is None:
            return ctypes.CDLL(path), path
        tried.append(why)
    lines = ["cannot load the plume shared library (libplume.so)."]
    if env:
        lines.append("PLUME_LIBRARY is set, so it was the only candidate:")
    else:
        lines.append("Tried:")
    lines += ["  - " + t for t in tried]
    lines.append("Set PLUME_LIBRARY=/path/to/libplume.so, or run `make install PREFIX=<prefix>` and "
                 "reinstall the package with PKG_CONFIG_PATH=<prefix>/lib/pkgconfig pip install ./python.")
    raise LibraryNotFoundError("\n".join(lines))


lib, LIBRARY_PATH = _load()

# --- declarations (include/plume/flat.h and base.h) ---------------------------------------------

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
_declare("plume_flat_scene_write_frames", _c_int, _c_void_p, _c_char_p, _msg_t, _c_long)
_declare("plume_flat_gltf_export", _c_int, _c_char_p, _c_char_p, _c_char_p, _c_char_p, _c_char_p, _msg_t, _c_long)


# --- helpers ------------------------------------------------------------------------------------

def strerror(status):
    """plume_strerror(status): the short name of a status code."""
    s = lib.plume_strerror(int(status))
    return s.decode("utf-8", "replace") if s else "status %d" % status


def version():
    """plume_version(): the library's version string, e.g. "3.0.0"."""
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

