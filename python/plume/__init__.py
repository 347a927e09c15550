"""plume: bird feathers as anisotropic elastic shells (Python bindings of the plume C library).

    import plume
    h = plume.homogenize()                      # moduli of the default barb layout (Pa)
    t = plume.traction(moduli=h, angle=45.0)    # macro traction test of a vane with those moduli
    f = plume.fit([t], start=h)                 # moduli fitted back to a curve
    with plume.Scene("scene.json") as s:        # a dynamic scene stepped in time
        s.step(10)
        s.write_frames("run/frames.h5")         # its state as a frame of a frames file
    run = plume.read_frames("run/frames.h5")    # a run read back: run.positions is (frames, nv, 3)
    plume.export_gltf("run/frames.h5", "run/scene.glb")  # the run for Blender and web viewers

The shared library libplume.so is found at import (PLUME_LIBRARY, the path recorded when the
package was installed, pkg-config, the source tree, the dynamic loader: see plume._native); importing raises plume.LibraryNotFoundError (an
ImportError) when none loads.
"""
from ._native import LIBRARY_PATH, LibraryNotFoundError, PlumeError
from .api import (MODULI, Curve, FitResult, HomogenizeResult, Scene, TractionResult, export_gltf, fit,
                  homogenize, openmp_serial, traction, version)
from .frames import Frames, read_frames

__version__ = "3.5.0"

__all__ = ["version", "openmp_serial", "homogenize", "traction", "fit", "Scene", "Curve", "HomogenizeResult",
           "TractionResult", "FitResult", "Frames", "read_frames", "export_gltf", "PlumeError", "LibraryNotFoundError", "LIBRARY_PATH",
           "MODULI", "__version__"]
