"""The PEP 517 build backend of oralfluor's Python package (pyproject.toml points here).

It needs nothing from PyPI (the build requirements are empty, so `pip install .` and
`python3 -m build` work offline with build isolation): it runs the project's own CMake build for
the Python that runs it (targets _oralfluor and oralfluor_python_files) and zips the package
folder it produces into a wheel (PEP 427: the files, METADATA, WHEEL and RECORD).

Where it builds: $OFL_BUILD_DIR when set (an existing build tree, e.g. the one `make` made; it must
be configured for this Python, which is checked), else build-py<version>/ in the source tree,
configured once with -DPython_EXECUTABLE=<this Python> (and ccache when installed).
Config settings (pip --config-settings / build -C): build-dir=..., jobs=N.
"""
import base64
import hashlib
import io
import os
import shutil
import subprocess
import sys
import sysconfig
import tarfile
import time
import zipfile

NAME = "oralfluor"
SOURCE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def _version():
    # The CMake project version (CMakeLists.txt: project(oralfluor VERSION x.y ...)).
    with open(os.path.join(SOURCE, "CMakeLists.txt")) as f:
        for line in f:
            if line.startswith("project(oralfluor VERSION"):
                return line.split("VERSION")[1].split()[0] + ".0"
    raise RuntimeError("CMakeLists.txt: no project(oralfluor VERSION ...) line")


def _metadata():
    readme = "oralfluor: a spectral path tracer and camera simulator for fluorescence imaging of the mouth.\n" \
             "See docs/python.md in the source tree.\n"
    return (f"Metadata-Version: 2.1\nName: {NAME}\nVersion: {_version()}\n"
            "Summary: Spectral path tracer and camera simulator for oral fluorescence imaging (Python module)\n"
            "Requires-Python: >=3.9\nRequires-Dist: numpy\nDescription-Content-Type: text/plain\n\n" + readme)


def _tag():
    impl = f"cp{sys.version_info.major}{sys.version_info.minor}"
    plat = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return f"{impl}-{impl}-{plat}"


def _run(cmd, **kw):
    print("oralfluor build:", " ".join(cmd), file=sys.stderr, flush=True)
    subprocess.run(cmd, check=True, stdout=sys.stderr, **kw)


def _build_dir(config):
    given = (config or {}).get("build-dir") or os.environ.get("OFL_BUILD_DIR")
    if given:
        return os.path.abspath(given), False
    return os.path.join(SOURCE, f"build-py{sys.version_info.major}.{sys.version_info.minor}"), True


def _configure(build, fresh):
    if not fresh or os.path.exists(os.path.join(build, "CMakeCache.txt")):
        return
    cmd = ["cmake", "-S", SOURCE, "-B", build, "-DCMAKE_BUILD_TYPE=Release", f"-DPython_EXECUTABLE={sys.executable}"]
    if shutil.which("ccache"):
        cmd.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
    _run(cmd)


def _check_python(package_dir):
    info = {}
    path = os.path.join(package_dir, "_build_info.py")
    if os.path.exists(path):
        exec(open(path).read(), info)
    built = info.get("python_version", "")
    here = f"{sys.version_info.major}.{sys.version_info.minor}"
    if not built.startswith(here + "."):
        raise RuntimeError(f"{package_dir}: the build tree is configured for Python {built or '?'} "
                           f"({info.get('python_executable', '?')}), not this Python {sys.version.split()[0]} "
                           f"({sys.executable}): unset OFL_BUILD_DIR to build one for this Python")


def _package_files(config):
    build, fresh = _build_dir(config)
    _configure(build, fresh)
    jobs = str((config or {}).get("jobs") or os.cpu_count() or 2)
    _run(["cmake", "--build", build, "--target", "_oralfluor", "oralfluor_python_files", "-j", jobs])
    package = os.path.join(build, "python", NAME)
    _check_python(package)
    files = []
    for name in sorted(os.listdir(package)):
        if name.endswith((".py", ".pyi", ".so")) or name == "py.typed":
            files.append((f"{NAME}/{name}", os.path.join(package, name)))
    if not any(n.endswith(".so") for n, _ in files):
        raise RuntimeError(f"{package}: no compiled module after the build")
    return files


def _record_line(arcname, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{arcname},sha256={digest},{len(data)}"


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    version, tag = _version(), _tag()
    dist_info = f"{NAME}-{version}.dist-info"
    wheel_name = f"{NAME}-{version}-{tag}.whl"
    entries = [(arc, open(path, "rb").read()) for arc, path in _package_files(config_settings)]
    entries.append((f"{dist_info}/METADATA", _metadata().encode()))
    entries.append((f"{dist_info}/WHEEL", (f"Wheel-Version: 1.0\nGenerator: oralfluor_build\nRoot-Is-Purelib: false\n"
                                           f"Tag: {tag}\n").encode()))
    record = [_record_line(a, d) for a, d in entries] + [f"{dist_info}/RECORD,,"]
    entries.append((f"{dist_info}/RECORD", ("\n".join(record) + "\n").encode()))
    path = os.path.join(wheel_directory, wheel_name)
    stamp = time.gmtime(int(os.environ.get("SOURCE_DATE_EPOCH", "315532800")))[:6]
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        for arc, data in entries:
            info = zipfile.ZipInfo(arc, stamp)
            info.external_attr = (0o755 if arc.endswith(".so") else 0o644) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info, data)
    return wheel_name


def _source_files():
    try:
        out = subprocess.run(["git", "-C", SOURCE, "ls-files", "-z"], check=True, capture_output=True).stdout
        return [f for f in out.decode().split("\0") if f and os.path.isfile(os.path.join(SOURCE, f))]
    except (OSError, subprocess.CalledProcessError):
        skip = {".git", "out"}
        files = []
        for root, dirs, names in os.walk(SOURCE):
            dirs[:] = [d for d in dirs if d not in skip and not d.startswith("build")]
            files += [os.path.relpath(os.path.join(root, n), SOURCE) for n in names]
        return sorted(files)


def build_sdist(sdist_directory, config_settings=None):
    base = f"{NAME}-{_version()}"
    path = os.path.join(sdist_directory, base + ".tar.gz")
    with tarfile.open(path, "w:gz", format=tarfile.PAX_FORMAT) as t:
        for f in _source_files():
            t.add(os.path.join(SOURCE, f), arcname=f"{base}/{f}", recursive=False)
        pkg = ("".join(_metadata().partition("\n\n")[0]) + "\n").encode()
        info = tarfile.TarInfo(f"{base}/PKG-INFO")
        info.size = len(pkg)
        t.addfile(info, io.BytesIO(pkg))
    return base + ".tar.gz"


def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []
