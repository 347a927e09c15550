"""The Python snippet of README.md runs as printed (the ```python block of the section "The
library"), from a scratch directory that holds the tree's data/ the way a clone's top does."""
import os
import re
import shutil
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
try:
    import plume  # noqa: F401  (loaded here, before the working directory changes)
except ModuleNotFoundError as e:
    if e.name != "plume":
        raise
    sys.path.insert(0, os.path.join(ROOT, "python"))
    import plume  # noqa: F401


def readme_python_blocks():
    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as f:
        text = f.read()
    return re.findall(r"^```python[^\n]*\n(.*?)^```", text, flags=re.S | re.M)


class ReadmeSnippet(unittest.TestCase):
    def test_readme_python_snippet_runs(self):
        snippets = readme_python_blocks()
        self.assertEqual(len(snippets), 1, "README.md should show exactly one Python snippet")
        code = snippets[0]
        self.assertLessEqual(len(code.strip().split("\n")), 12, "the README's Python snippet is meant to be short")
        work = tempfile.mkdtemp(prefix="plume-readme-")
        cwd = os.getcwd()
        try:
            os.symlink(os.path.join(ROOT, "data"), os.path.join(work, "data"))
            os.chdir(work)
            scope = {"__name__": "__readme__"}
            exec(compile(code, "README.md (python block)", "exec"), scope)
            # what the snippet promises: curves as numpy arrays, a ParaView series on disk
            t = scope["t"]
            self.assertEqual(len(t.strain), len(t.stress))
            self.assertGreater(len(t.strain), 1)
            self.assertTrue(os.path.exists(os.path.join(work, "out", "strip", "frames.pvd")))
        finally:
            os.chdir(cwd)
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    unittest.main()
