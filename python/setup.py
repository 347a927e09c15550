"""The install hook of the plume package: when the package is built (pip install ./python), it
records where libplume is in plume/_install.py, so that `import plume` finds the library in a new
shell with no environment variable. The project's metadata is in pyproject.toml.

The library is looked for as plume/_locate.py says (at_install): PLUME_LIBRARY, then pkg-config with
the installer's PKG_CONFIG_PATH, then the source tree's build/. When none is found the install still
succeeds: it says so, and the import then looks as it always does (plume/_native.py).
"""
import importlib.util
import os
import sys

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = os.path.dirname(os.path.abspath(__file__))


def _locate_module():
    """plume/_locate.py, loaded on its own: importing the package would load the library."""
    spec = importlib.util.spec_from_file_location("_plume_locate", os.path.join(HERE, "plume", "_locate.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


class build_py_recording(build_py):
    """build_py, then plume/_install.py in the build tree naming the library found now."""

    def run(self):
        super().run()
        locate = _locate_module()
        path, how, notes = locate.at_install(os.path.join(HERE, "plume"))
        target = os.path.join(self.build_lib, "plume", "_install.py")
        with open(target, "w") as f:
            f.write('"""Written by setup.py when this copy of plume was installed: where libplume was '
                    'then."""\n')
            f.write("LIBRARY = %r\n" % path)
            f.write("FOUND_BY = %r\n" % how)
            f.write("NOTES = %r\n" % (notes,))
        if path:
            print("plume: libplume recorded for import: %s (found by %s)" % (path, how), file=sys.stderr)
        else:
            print("plume: WARNING: libplume not found at install (%s); `import plume` will look for it "
                  "at import time (PLUME_LIBRARY, pkg-config, the dynamic loader). To record it, "
                  "reinstall with PKG_CONFIG_PATH=<prefix>/lib/pkgconfig or PLUME_LIBRARY=<path>"
                  % "; ".join(notes), file=sys.stderr)


setup(cmdclass={"build_py": build_py_recording})
