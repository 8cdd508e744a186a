"""dynmesh_backend: the in-tree PEP 517 build backend of the Python module (pyproject.toml).

Purpose: `pip install --no-build-isolation .` builds the module through the project's own
CMake (one build: the same sources, options and compiler flags as every other target) and
packs it into a wheel, offline: nothing is downloaded, and the only tools are CMake, a C++
compiler and the Debian packages dev.sh installs (pybind11, NumPy).

What it runs: CMake configures build/python-wheel/ under the source tree (kept between
installs, so a second install rebuilds only what changed) with DYNMESH_PYTHON=ON, no tests,
benchmarks, examples or command, Release, and Python3_EXECUTABLE = the interpreter pip runs;
it builds the target dynmesh_python and zips build/python-wheel/python/dynmesh/ (the
extension and the package's .py files) with the .dist-info the wheel format asks for.
DYNMESH_WHEEL_BUILD_DIR overrides the build directory; JOBS (as for dev.sh) the parallelism,
by default the CPUs the process may run on.
Invariants: the wheel holds exactly the package directory CMake laid out; its version is the
project's (CMakeLists.txt); its tag names this interpreter and platform (the module is
compiled for them).
Complexity: one CMake build of the libraries and the module.
"""
import base64
import hashlib
import os
import pathlib
import re
import shutil
import subprocess
import sys
import sysconfig
import zipfile

ROOT = pathlib.Path(__file__).resolve().parents[3]
NAME = "dynmesh"
SUMMARY = "Dynamic quality meshes of changing point sets (self-adjusting computation)"


def _version():
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(\s*\w+\s+VERSION\s+([0-9.]+)", text).group(1)


def _tag():
    impl = f"cp{sys.version_info.major}{sys.version_info.minor}"
    abi = impl + sys.abiflags
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return f"{impl}-{abi}-{platform}"


def _dist_info():
    return f"{NAME}-{_version()}.dist-info"


def _metadata():
    return (f"Metadata-Version: 2.1\nName: {NAME}\nVersion: {_version()}\nSummary: {SUMMARY}\n"
            "License: see the project's repository\nRequires-Python: >=3.9\nRequires-Dist: numpy\n")


def _wheel_file():
    return f"Wheel-Version: 1.0\nGenerator: dynmesh_backend\nRoot-Is-Purelib: false\nTag: {_tag()}\n"


def get_requires_for_build_wheel(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    info = pathlib.Path(metadata_directory) / _dist_info()
    info.mkdir(parents=True, exist_ok=True)
    (info / "METADATA").write_text(_metadata())
    (info / "WHEEL").write_text(_wheel_file())
    return info.name


def _run(cmd):
    print("dynmesh_backend:", " ".join(map(str, cmd)), file=sys.stderr, flush=True)
    subprocess.run(list(map(str, cmd)), check=True, stdout=sys.stderr)


def _cpus():
    """The CPUs this process may run on, as dev.sh's nproc counts them: in a container limited
    to a few CPUs (a cpuset), those, not the host's (os.cpu_count(), which reads /sys or /proc)."""
    try:
        return len(os.sched_getaffinity(0)) or 1
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def _build_package():
    """Configures and builds dynmesh_python; returns the package directory CMake laid out."""
    build = pathlib.Path(os.environ.get("DYNMESH_WHEEL_BUILD_DIR", ROOT / "build" / "python-wheel"))
    configure = ["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release", "-DDYNMESH_PYTHON=ON",
                 "-DSAC_BUILD_TESTS=OFF", "-DSAC_BUILD_BENCH=OFF", "-DSAC_BUILD_EXAMPLES=OFF",
                 "-DDYNMESH_BUILD_TOOLS=OFF", f"-DPython3_EXECUTABLE={sys.executable}"]
    if shutil.which("ninja") and not (build / "CMakeCache.txt").exists():
        configure += ["-G", "Ninja"]
    _run(configure)
    _run(["cmake", "--build", build, "--target", "dynmesh_python", "-j", os.environ.get("JOBS", _cpus())])
    package = build / "python" / NAME
    if not any(package.glob("_dynmesh*.so")):
        raise RuntimeError(f"dynmesh_backend: no extension module in {package}")
    return package


def _record_line(arcname, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{arcname},sha256={digest},{len(data)}"


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    package = _build_package()
    wheel_name = f"{NAME}-{_version()}-{_tag()}.whl"
    files = [(f"{NAME}/{p.name}", p.read_bytes()) for p in sorted(package.iterdir())
             if p.is_file() and (p.suffix == ".py" or p.name.startswith("_dynmesh"))]
    info = _dist_info()
    files += [(f"{info}/METADATA", _metadata().encode()), (f"{info}/WHEEL", _wheel_file().encode())]
    record = "\n".join(_record_line(name, data) for name, data in files) + f"\n{info}/RECORD,,\n"
    path = pathlib.Path(wheel_directory) / wheel_name
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as whl:
        for name, data in files:
            whl.writestr(name, data)
        whl.writestr(f"{info}/RECORD", record)
    return wheel_name
