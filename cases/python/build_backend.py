"""The PEP 517 build backend of `pip install .`: setuptools' own backend, run with the setup
script below instead of a top-level setup.py. The extension mbdae._core is built by CMake (the
project's CMakeLists.txt, target mbdae_python) and copied into the wheel with the package's
Python files, its type stubs and the quick-look video module (cases/animation/video.py as
mbdae._video). One version number: project(mbdae VERSION ...) in CMakeLists.txt."""
import os
import re
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

from setuptools import build_meta as _build_meta

ROOT = Path(__file__).resolve().parents[2]


def version():
    """The version of project(mbdae VERSION x.y.z) in the top CMakeLists.txt."""
    m = re.search(r"project\(\s*mbdae\s+VERSION\s+([0-9.]+)", (ROOT / "CMakeLists.txt").read_text())
    if not m:
        raise RuntimeError("CMakeLists.txt: no 'project(mbdae VERSION x.y.z ...)'")
    return m.group(1)


def build_dir():
    return Path(os.environ.get("MBDAE_BUILD_DIR", ROOT / "build" / "pip")).resolve()


def cmake_build_module():
    """Configures (if needed) and builds the extension; returns the path of the built module."""
    build = build_dir()
    if not (build / "CMakeCache.txt").exists():
        build.mkdir(parents=True, exist_ok=True)
        launcher = ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"] if shutil.which("ccache") else []
        subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                        f"-DPython_EXECUTABLE={sys.executable}", *launcher], check=True)
    jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", "2")
    subprocess.run(["cmake", "--build", str(build), "-j", jobs, "--target", "mbdae_python"], check=True)
    suffix = sysconfig.get_config_var("EXT_SUFFIX")
    module = build / "python" / "mbdae" / ("_core" + suffix)
    if not module.exists():
        found = sorted((build / "python" / "mbdae").glob("_core*.so"))
        raise RuntimeError(f"{module} not built (found: {', '.join(map(str, found)) or 'none'}); the build "
                           f"folder {build} was configured for another Python: set MBDAE_BUILD_DIR")
    return module


def setup_script():
    from setuptools import Extension, setup
    from setuptools.command.build_ext import build_ext
    from setuptools.command.build_py import build_py

    class CMakeExtension(build_ext):
        def build_extension(self, ext):
            target = Path(self.get_ext_fullpath(ext.name))
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(cmake_build_module(), target)

    class WithVideo(build_py):
        def run(self):
            super().run()
            shutil.copy2(ROOT / "cases" / "animation" / "video.py", Path(self.build_lib) / "mbdae" / "_video.py")

    work = os.path.relpath(build_dir() / "setuptools", ROOT)
    setup(version=version(), packages=["mbdae"], package_dir={"mbdae": "cases/python/mbdae"},
          package_data={"mbdae": ["py.typed", "*.pyi"]},
          ext_modules=[Extension("mbdae._core", sources=[])],
          cmdclass={"build_ext": CMakeExtension, "build_py": WithVideo},
          options={"build": {"build_base": work}, "egg_info": {"egg_base": work}}, zip_safe=False)


class _Backend(_build_meta._BuildMetaBackend):
    def run_setup(self, setup_script="setup.py"):
        os.makedirs(build_dir() / "setuptools", exist_ok=True)
        setup_script_main()


def setup_script_main():
    saved = sys.argv
    try:
        setup_script()
    finally:
        sys.argv = saved


_backend = _Backend()
get_requires_for_build_wheel = _backend.get_requires_for_build_wheel
get_requires_for_build_sdist = _backend.get_requires_for_build_sdist
get_requires_for_build_editable = _backend.get_requires_for_build_editable
prepare_metadata_for_build_wheel = _backend.prepare_metadata_for_build_wheel
prepare_metadata_for_build_editable = _backend.prepare_metadata_for_build_editable
build_wheel = _backend.build_wheel
build_sdist = _backend.build_sdist
build_editable = _backend.build_editable
