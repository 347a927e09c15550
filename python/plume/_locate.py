"""Where libplume is: the searches shared by the import (plume._native) and the install (setup.py,
which records what it finds in plume/_install.py).

Nothing here loads anything at import, and it imports nothing of plume: setup.py runs it from the
source tree before the package exists. The soname (libplume.so.N) is never written here: it is read
from the library file itself (its ELF DT_SONAME), so a new soname needs no change in Python.
"""
import ctypes
import glob
import os
import re
import shutil
import struct
import subprocess

#: The unversioned name of the shared library: the link `make install` puts beside the real file.
DEV_NAME = "libplume.so"


def elf_soname(path):
    """The DT_SONAME of the ELF shared library at path (e.g. "libplume.so.0"), or None when the file
    cannot be read, is not ELF or has none."""
    try:
        with open(path, "rb") as f:
            ident = f.read(16)
            if len(ident) < 16 or ident[:4] != b"\x7fELF" or ident[4] not in (1, 2) or ident[5] not in (1, 2):
                return None
            end = "<" if ident[5] == 1 else ">"
            if ident[4] == 2:  # ELFCLASS64
                head, shdr, dyn = end + "HHIQQQIHHHHHH", end + "IIQQQQIIQQ", end + "qQ"
            else:
                head, shdr, dyn = end + "HHIIIIIHHHHHH", end + "IIIIIIIIII", end + "iI"
            fields = struct.unpack(head, f.read(struct.calcsize(head)))
            shoff, shentsize, shnum = fields[5], fields[10], fields[11]
            sections = []
            for i in range(shnum):
                f.seek(shoff + i * shentsize)
                sections.append(struct.unpack(shdr, f.read(struct.calcsize(shdr))))
            for sh in sections:  # (name, type, flags, addr, offset, size, link, info, align, entsize)
                if sh[1] != 6:   # SHT_DYNAMIC; its sh_link is the string table of the entries
                    continue
                f.seek(sh[4])
                raw = f.read(sh[5])
                step = struct.calcsize(dyn)
                for off in range(0, len(raw) - step + 1, step):
                    tag, val = struct.unpack_from(dyn, raw, off)
                    if tag == 0:      # DT_NULL
                        break
                    if tag == 14:     # DT_SONAME
                        f.seek(sections[sh[6]][4] + val)
                        name = f.read(256).split(b"\0", 1)[0]
                        return name.decode("utf-8", "replace") or None
    except (OSError, struct.error, IndexError, ValueError):
        return None
    return None


def versioned(path):
    """The absolute path a program linked against the library at `path` would load: the file
    named by its soname in the same directory (libdir/libplume.so.N, which follows minor
    upgrades) when that exists, else the file `path` itself with its links resolved."""
    path = os.path.abspath(path)
    soname = elf_soname(path)
    if soname:
        beside = os.path.join(os.path.dirname(path), soname)
        if os.path.exists(beside):
            return beside
    return os.path.realpath(path)


def in_libdir(libdir):
    """The library of a library directory: versioned(libdir/libplume.so), or when only versioned
    names are there (libplume.so.N), the one with the highest N; None when there is none."""
    dev = os.path.join(libdir, DEV_NAME)
    if os.path.exists(dev):
        return versioned(dev)
    majors = []
    for p in glob.glob(os.path.join(glob.escape(libdir), DEV_NAME + ".*")):
        m = re.fullmatch(re.escape(DEV_NAME) + r"\.(\d+)", os.path.basename(p))
        if m:
            majors.append((int(m.group(1)), p))
    return max(majors)[1] if majors else None


def pkg_config():
    """(path, note): the library under `pkg-config --variable=libdir plume` with the environment's
    PKG_CONFIG_PATH, or (None, why not)."""
    exe = shutil.which("pkg-config")
    if exe is None:
        return None, "pkg-config: not installed"
    try:
        out = subprocess.run([exe, "--variable=libdir", "plume"], capture_output=True, text=True,
                             timeout=10)
    except (OSError, subprocess.SubprocessError) as e:
        return None, "pkg-config: %s" % e
    libdir = out.stdout.strip()
    if out.returncode != 0 or not libdir:
        return None, "pkg-config: does not know plume (PKG_CONFIG_PATH=%s)" % os.environ.get("PKG_CONFIG_PATH", "")
    found = in_libdir(libdir)
    if found is None:
        return None, "pkg-config: libdir %s holds no %s" % (libdir, DEV_NAME)
    return found, None


def source_tree(package_dir):
    """(path, note): <package_dir>/../../build/libplume.so of a source checkout (after `make`), or
    (None, why not). The build directory's link is kept as it is: it follows every rebuild."""
    tree = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(package_dir))), "build", DEV_NAME)
    if os.path.exists(tree):
        return tree, None
    return None, "source tree: no %s" % tree


def check(path):
    """None when the library at path loads and has the flat interface, else why not."""
    try:
        lib = ctypes.CDLL(path)
    except OSError as e:
        return "%s: %s" % (path, e)
    if not hasattr(lib, "plume_flat_scene_open"):
        return "%s: loads but has no plume_flat_* functions (plume older than 0.2?)" % path
    return None


def at_install(package_dir):
    """What setup.py records: (path, how, notes). The first of PLUME_LIBRARY, pkg-config (with the
    installer's PKG_CONFIG_PATH) and the source tree's build/ that loads, as an absolute path (an
    installed library's versioned file); path None when none does, notes saying what was tried. A
    PLUME_LIBRARY that does not load is a ValueError: it was an explicit choice."""
    env = os.environ.get("PLUME_LIBRARY")
    if env:
        why = check(env)
        if why:
            raise ValueError("PLUME_LIBRARY is set but the library cannot be used: " + why)
        return versioned(env), "PLUME_LIBRARY", []
    notes = []
    for how, (path, note) in (("pkg-config", pkg_config()), ("the source tree", source_tree(package_dir))):
        if path is None:
            notes.append(note)
            continue
        why = check(path)
        if why is None:
            # an installed library by its soname; a checkout's build/ by its link, which follows
            # every rebuild (a new soname's file appears beside the old one, which stays)
            return (versioned(path) if how == "pkg-config" else os.path.abspath(path)), how, notes
        notes.append("%s: %s" % (how, why))
    return None, None, notes
