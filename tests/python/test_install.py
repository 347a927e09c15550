"""pip install of the package as a user does it (and as CI does): a fresh venv, offline, the library
found at install time through pkg-config and recorded (setup.py, plume/_install.py); then `import
plume` in a clean environment (env -i: no PKG_CONFIG_PATH, PLUME_LIBRARY or PYTHONPATH); and, after
`make install PREFIX=...`, the chain example of docs/examples/python run that way.
"""
import glob
import os
import re
import shutil
import subprocess
import sys
import tempfile
import textwrap
import unittest

from test_plume import ROOT, PACKAGE_DIR, plume, _native

from plume import _locate


def _readelf_soname(path):
    """The soname readelf prints for path, or None without readelf."""
    exe = shutil.which("readelf")
    if exe is None:
        return None
    out = subprocess.run([exe, "-d", path], capture_output=True, text=True).stdout
    m = re.search(r"\(SONAME\).*\[(.*)\]", out)
    return m.group(1) if m else ""


def _venv_python(tmp):
    """A fresh venv in tmp/venv seeing the system's numpy and h5py; its python, or None when the
    distribution's venv module (python3-venv) is missing."""
    p = subprocess.run(["/usr/bin/python3", "-m", "venv", "--system-site-packages", os.path.join(tmp, "venv")],
                       capture_output=True, text=True, timeout=300)
    python = os.path.join(tmp, "venv", "bin", "python")
    return python if p.returncode == 0 and os.path.exists(python) else None


def _pip_install(python, src, env):
    return subprocess.run([python, "-m", "pip", "install", "-v", "--no-build-isolation", "--no-deps",
                           "--no-index", src], env=env, capture_output=True, text=True, timeout=600)


def _clean_run(python, cwd, code, *args):
    """python -c code (or, with code None, python args...) in a clean environment from cwd: no
    PLUME_*, PYTHONPATH, LD_LIBRARY_PATH or PKG_CONFIG_PATH. (returncode, stdout, stderr)."""
    argv = [python] + (["-c", code] if code is not None else []) + list(args)
    p = subprocess.run(["env", "-i", "HOME=" + cwd, "PATH=/usr/bin:/bin"] + argv, cwd=cwd,
                       capture_output=True, text=True, timeout=120)
    return p.returncode, p.stdout.strip(), p.stderr


class TestSoname(unittest.TestCase):
    def test_soname_of_the_loaded_library(self):
        real = os.path.realpath(plume.LIBRARY_PATH if os.sep in plume.LIBRARY_PATH else _native.lib._name)
        want = _readelf_soname(real)
        if want is None:
            self.skipTest("no readelf to compare with")
        self.assertTrue(want.startswith("libplume.so."), want)
        self.assertEqual(_locate.elf_soname(real), want)

    def test_not_elf(self):
        self.assertIsNone(_locate.elf_soname(os.path.join(ROOT, "README.md")))
        self.assertIsNone(_locate.elf_soname("/nonexistent/libplume.so"))


@unittest.skipUnless(os.path.exists("/usr/bin/python3"), "no /usr/bin/python3")
class TestPipInstall(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        # one venv for the class (the slow part); each test installs into it afresh
        cls.venv_dir = os.path.realpath(tempfile.mkdtemp(prefix="plume-venv-"))
        cls.python = _venv_python(cls.venv_dir)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.venv_dir, True)

    def setUp(self):
        if self.python is None:
            self.skipTest("python3 -m venv is unavailable (python3-venv)")
        self.tmp = os.path.realpath(tempfile.mkdtemp(prefix="plume-pip-"))
        self.addCleanup(shutil.rmtree, self.tmp, True)
        subprocess.run([self.python, "-m", "pip", "uninstall", "-y", "-q", "plume"], capture_output=True, timeout=120)
        # the package alone, away from the source tree (no ../build to fall back on)
        self.src = os.path.join(self.tmp, "src", "python")
        shutil.copytree(os.path.dirname(PACKAGE_DIR), self.src,
                        ignore=shutil.ignore_patterns("__pycache__", "build", "*.egg-info"))
        self.env = {k: v for k, v in os.environ.items()
                    if k not in ("PLUME_LIBRARY", "PKG_CONFIG_PATH", "PYTHONPATH")}
        self.env["PKG_CONFIG_LIBDIR"] = os.path.join(self.tmp, "empty")  # pkg-config: only what we give
        os.makedirs(self.env["PKG_CONFIG_LIBDIR"])
        self.run_dir = os.path.join(self.tmp, "run")
        os.makedirs(self.run_dir)

    def _site_install_file(self):
        found = glob.glob(os.path.join(self.venv_dir, "venv", "lib", "python*", "site-packages", "plume", "_install.py"))
        self.assertEqual(len(found), 1, found)
        scope = {}
        with open(found[0]) as f:
            exec(f.read(), scope)
        return scope

    def test_recorded_through_pkg_config(self):
        if shutil.which("pkg-config") is None:
            self.skipTest("no pkg-config")
        real = os.path.realpath(plume.LIBRARY_PATH if os.sep in plume.LIBRARY_PATH else _native.lib._name)
        soname = _readelf_soname(real) or _locate.elf_soname(real)
        # a prefix laid out as `make install` lays it out: the file, its soname link, the dev link
        libdir = os.path.join(self.tmp, "prefix", "lib")
        os.makedirs(os.path.join(libdir, "pkgconfig"))
        shutil.copy(real, os.path.join(libdir, os.path.basename(real)))
        os.symlink(os.path.basename(real), os.path.join(libdir, soname))
        os.symlink(os.path.basename(real), os.path.join(libdir, "libplume.so"))
        with open(os.path.join(libdir, "pkgconfig", "plume.pc"), "w") as f:
            f.write(textwrap.dedent("""\
                prefix=%s
                libdir=${prefix}/lib
                Name: plume
                Description: test
                Version: %s
                Libs: -L${libdir} -lplume
                """ % (os.path.dirname(libdir), plume.version())))
        env = dict(self.env, PKG_CONFIG_PATH=os.path.join(libdir, "pkgconfig"))
        p = _pip_install(self.python, self.src, env)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        rec = self._site_install_file()
        self.assertEqual(rec["LIBRARY"], os.path.join(libdir, soname))
        self.assertEqual(rec["FOUND_BY"], "pkg-config")
        rc, out, err = _clean_run(self.python, self.run_dir, "import plume; print(plume.LIBRARY_PATH, plume.version())")
        self.assertEqual(rc, 0, err)
        self.assertEqual(out, "%s %s" % (os.path.join(libdir, soname), plume.version()))

    def test_example_after_make_install(self):
        """The user's path end to end: `make install PREFIX=...` of the build under test, pip
        install with pkg-config finding it, then the chain example (layout -> moduli file -> scene
        -> frames read back) run by the venv's python with no environment variable set."""
        if shutil.which("pkg-config") is None or shutil.which("make") is None:
            self.skipTest("no pkg-config or make")
        real = os.path.realpath(plume.LIBRARY_PATH if os.sep in plume.LIBRARY_PATH else _native.lib._name)
        prefix = os.path.join(self.tmp, "prefix")
        # the build the suite runs against: everything is up to date, install only copies (as
        # test_exports_installed_example)
        p = subprocess.run(["make", "-s", "-C", ROOT, "BUILD=" + os.path.dirname(real), "install", "PREFIX=" + prefix],
                           capture_output=True, text=True, timeout=600)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        env = dict(self.env, PKG_CONFIG_PATH=os.path.join(prefix, "lib", "pkgconfig"))
        p = _pip_install(self.python, self.src, env)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertTrue(self._site_install_file()["LIBRARY"].startswith(os.path.join(prefix, "lib") + os.sep))
        example = os.path.join(ROOT, "docs", "examples", "python", "scene_from_layout.py")
        rc, out, err = _clean_run(self.python, self.run_dir, None, example)
        self.assertEqual(rc, 0, out + err)
        self.assertIn("from " + os.path.join(prefix, "lib"), out)
        self.assertEqual(out.splitlines()[-1], "scene example: ok", out + err)
        self.assertEqual(os.listdir(self.run_dir), [])

    def test_nothing_found_installs_and_says_so(self):
        p = _pip_install(self.python, self.src, self.env)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertIn("libplume not found at install", p.stdout + p.stderr)
        rec = self._site_install_file()
        self.assertIsNone(rec["LIBRARY"])
        self.assertTrue(any("pkg-config" in n for n in rec["NOTES"]), rec["NOTES"])
        rc, out, err = _clean_run(self.python, self.run_dir, "import plume")
        if rc != 0:  # unless the loader finds an installed plume on its own
            self.assertIn("LibraryNotFoundError", err)
            self.assertIn("nothing was found then", err)

    def test_bad_plume_library_at_install_fails_naming_it(self):
        env = dict(self.env, PLUME_LIBRARY=os.path.join(self.tmp, "nonexistent", "libplume.so"))
        p = _pip_install(self.python, self.src, env)
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("PLUME_LIBRARY is set but the library cannot be used", p.stdout + p.stderr)
        self.assertIn(env["PLUME_LIBRARY"], p.stdout + p.stderr)


if __name__ == "__main__":
    unittest.main()
