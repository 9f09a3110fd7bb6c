"""oralfluor installs as a Python package: `pip install .` into a virtual environment made from
/usr/bin/python3 (offline: the build backend needs nothing from PyPI), `python3 -m build` makes the
wheel (its sdist holds the tracked sources), and the installed package passes the tests that exercise its entry points, imported
from the environment and not from the build tree. The .pyi stubs name every argument the compiled
functions take (an editor's completion is what the module accepts).

The build reuses the build tree the tests run from (OFL_BUILD_DIR), so this costs a link check, not
a compile. OFL_TEST_INSTALLED_ALL=1 runs every test file against the installed package."""
import ast
import glob
import inspect
import os
import re
import shutil
import subprocess
import sys
import tarfile
import zipfile

import pytest

import oralfluor as ofl
from oralfluor import _oralfluor
from conftest import BINARY, ROOT

BUILD = os.path.dirname(BINARY)
STUBS = os.path.join(ROOT, "python", "oralfluor", "_oralfluor.pyi")


def offline_env(**extra):
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(OFL_BUILD_DIR=BUILD, PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1", **extra)
    return env


def run(cmd, **kw):
    p = subprocess.run(cmd, capture_output=True, text=True, **kw)
    assert p.returncode == 0, f"{' '.join(map(str, cmd))} exited {p.returncode}:\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}"
    return p


@pytest.fixture(scope="module")
def venv(tmp_path_factory):
    if sys.executable != "/usr/bin/python3":
        pytest.skip("the package test builds for Debian's /usr/bin/python3")
    d = tmp_path_factory.mktemp("venv") / "env"
    # --system-site-packages: numpy (and pytest) come from Debian's python3-numpy, not from PyPI.
    run(["/usr/bin/python3", "-m", "venv", "--system-site-packages", str(d)])
    run([str(d / "bin" / "pip"), "install", "--no-cache-dir", ROOT], env=offline_env(), cwd=str(d))
    return d


def test_pip_install_puts_a_working_package_in_the_environment(venv, tmp_path):
    py = str(venv / "bin" / "python")
    code = "import oralfluor, sys; print(oralfluor.__file__); print(oralfluor.fluorophores()[0]['name'])"
    p = run([py, "-c", code], env=offline_env(), cwd=str(tmp_path))
    where, first = p.stdout.split()
    assert where.startswith(str(venv)) and "site-packages" in where
    assert first == ofl.fluorophores()[0]["name"]
    files = os.listdir(os.path.dirname(where))
    assert {"py.typed", "_oralfluor.pyi", "_build_info.py"} <= set(files)


def test_installed_package_passes_the_tests(venv, tmp_path):
    tests = os.path.join(ROOT, "python", "tests")
    if os.environ.get("OFL_TEST_INSTALLED_ALL"):
        files = sorted(f for f in glob.glob(os.path.join(tests, "test_*.py")) if not f.endswith("test_package.py"))
    else:  # every entry point and its conversions (diagnose runs left out: seconds each): every binding file
        files = [os.path.join(tests, f) for f in ("test_arguments.py", "test_fuzz_arguments.py")] + ["-k", "not diagnose"]
    p = subprocess.run([str(venv / "bin" / "python"), "-m", "pytest", "-q", "-p", "no:cacheprovider",
                        "--rootdir", str(tmp_path), *files], capture_output=True, text=True, cwd=str(tmp_path),
                       env=offline_env(OFL_BINARY=BINARY, OFL_SOURCE_DIR=ROOT))
    assert p.returncode == 0, p.stdout[-4000:] + p.stderr[-2000:]
    assert re.search(r"\d+ passed", p.stdout) and " failed" not in p.stdout


def test_uninstall_removes_what_pip_installed(venv, tmp_path):
    # Last: what pip recorded is what is there, so uninstall leaves nothing behind.
    py = str(venv / "bin" / "python")
    where = os.path.dirname(run([py, "-c", "import oralfluor; print(oralfluor.__file__)"], env=offline_env(),
                                cwd=str(tmp_path)).stdout.strip())
    run([str(venv / "bin" / "pip"), "uninstall", "-y", "oralfluor"], env=offline_env())
    assert not os.path.exists(where)
    assert subprocess.run([py, "-c", "import oralfluor"], env=offline_env(), cwd=str(tmp_path)).returncode != 0


def test_python_m_build_makes_a_wheel(tmp_path):
    if subprocess.run(["/usr/bin/python3", "-c", "import build"]).returncode:
        pytest.fail("python3-build (Debian) is missing: .ci/install-deps.sh installs it")
    out = tmp_path / "dist"
    run(["/usr/bin/python3", "-m", "build", "--wheel", "--outdir", str(out), ROOT], env=offline_env(), cwd=str(tmp_path))
    wheels = glob.glob(str(out / "oralfluor-*-cp3*-linux_*.whl"))
    assert len(wheels) == 1
    with zipfile.ZipFile(wheels[0]) as z:
        names = z.namelist()
        record = z.read(next(n for n in names if n.endswith("/RECORD"))).decode()
    assert any(re.fullmatch(r"oralfluor/_oralfluor\.cpython-\d+-.*\.so", n) for n in names)
    assert "oralfluor/__init__.py" in names and "oralfluor/_oralfluor.pyi" in names
    assert all(n in record for n in names)


def test_sdist_holds_the_tracked_sources(tmp_path):
    # The backend's sdist (what `python3 -m build --sdist` asks for), called directly: the files git
    # tracks, nothing from build trees, and PKG-INFO.
    sys.path.insert(0, os.path.join(ROOT, "python", "packaging"))
    import oralfluor_build
    name = oralfluor_build.build_sdist(str(tmp_path))
    with tarfile.open(tmp_path / name) as t:
        members = [m.split("/", 1)[1] for m in t.getnames()]
    tracked = subprocess.run(["git", "-C", ROOT, "ls-files"], capture_output=True, text=True)
    if tracked.returncode == 0:
        assert sorted(m for m in members if m != "PKG-INFO") == sorted(tracked.stdout.split())
    assert "PKG-INFO" in members and "pyproject.toml" in members and "CMakeLists.txt" in members
    assert not any(m.startswith(("build/", "build-py")) for m in members)


def runtime_parameters(fn):
    """Parameter names from pybind11's signature line, e.g. "read_exr(path: object) -> ..."."""
    first = fn.__doc__.splitlines()[0]
    inside = first[first.index("(") + 1:first.rindex(") ->")]
    names = []
    depth = 0
    token = ""
    for ch in inside + ",":
        if ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
        if ch == "," and depth == 0:
            if token.strip():
                names.append(token.split(":")[0].strip())
            token = ""
        else:
            token += ch
    return [n for n in names if n != "self"]


def test_stubs_name_every_argument_the_module_takes():
    tree = ast.parse(open(STUBS).read())
    stub_funcs = {n.name: n for n in tree.body if isinstance(n, ast.FunctionDef)}
    stub_classes = {n.name: {m.name: m for m in n.body if isinstance(m, ast.FunctionDef)}
                    for n in tree.body if isinstance(n, ast.ClassDef)}
    args = lambda f: [a.arg for a in f.args.args + f.args.kwonlyargs if a.arg != "self"]  # noqa: E731
    checked = 0
    for name, obj in vars(_oralfluor).items():
        if name.startswith("__"):
            continue
        if inspect.isclass(obj) and issubclass(obj, BaseException):
            assert name in stub_classes, name
        elif inspect.isclass(obj):
            assert name in stub_classes, f"class {name} has no stub"
            for meth, f in vars(obj).items():
                doc = getattr(f, "__doc__", None) or ""
                if meth.startswith("_") and meth != "__init__" or not callable(f) or not doc.startswith(meth + "("):
                    continue  # not a pybind11 function (inherited slots, properties)
                if meth == "__init__":
                    assert runtime_parameters(f) == args(stub_classes[name]["__init__"]), name
                else:
                    assert meth in stub_classes[name], f"{name}.{meth} has no stub"
                    assert runtime_parameters(f) == args(stub_classes[name][meth]), f"{name}.{meth}"
                checked += 1
            for prop, p in vars(obj).items():
                if isinstance(p, property):
                    assert prop in stub_classes[name], f"{name}.{prop} has no stub"
        elif callable(obj):
            assert name in stub_funcs, f"{name} has no stub"
            assert runtime_parameters(obj) == args(stub_funcs[name]), name
            checked += 1
    assert checked >= 25
