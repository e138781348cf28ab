"""`cmake --install` into a temporary prefix gives a working installation (README, "Install";
cmake/Install.cmake): the program on PATH names its commit and makes a map, a man page per
subcommand that groff reads without a warning, a bash completion that offers every option of every
subcommand, the docs, and the Python module that Debian's python3 imports from the prefix's
dist-packages. Nothing installed loads a file of the build directory.

run by CTest (tests/tools/CMakeLists.txt) after the whole build, which it installs:
STRATA_BUILD_DIR, STRATA_SOURCE_DIR, STRATA_PYTHON (the interpreter the module is built for) and
STRATA_PYTHON_INSTALL_DIR (the module's folder relative to the prefix). Without the module
(pybind11 not found) CTest deselects the module's test.
"""
import json
import os
import pathlib
import re
import subprocess

import pytest

BUILD = pathlib.Path(os.environ["STRATA_BUILD_DIR"]).resolve()
SOURCE = pathlib.Path(os.environ["STRATA_SOURCE_DIR"]).resolve()
PYTHON = os.environ.get("STRATA_PYTHON", "/usr/bin/python3")
SITE = os.environ.get("STRATA_PYTHON_INSTALL_DIR", "")


def run(*args, **kwargs) -> subprocess.CompletedProcess:
    done = subprocess.run([str(a) for a in args], capture_output=True, text=True, **kwargs)
    assert done.returncode == 0, f"{' '.join(map(str, args))}: {done.stdout}{done.stderr}"
    return done


@pytest.fixture(scope="module")
def prefix(tmp_path_factory):
    prefix = tmp_path_factory.mktemp("prefix")
    run("cmake", "--install", BUILD, "--prefix", prefix)
    return prefix


@pytest.fixture(scope="module")
def env(prefix):
    """strata found on PATH, as after installing into /usr/local."""
    return dict(os.environ, PATH=f"{prefix / 'bin'}:{os.environ['PATH']}")


def options_in(help_text):
    """The option names an entry of CLI11's help begins with: "  -h,--help  ..." gives both."""
    names = []
    for line in help_text.splitlines():
        match = re.match(r"  (-\S+)", line)
        if match:
            names += match.group(1).split(",")
    return names


def subcommands_in(help_text):
    lines = help_text.split("\nSubcommands:\n", 1)
    return re.findall(r"^  (\S+)", lines[1], flags=re.M) if len(lines) == 2 else []


@pytest.fixture(scope="module")
def commands(env):
    """Every command path with its --help: [], ["integrate"], ..., ["session", "list"]."""
    paths, found = [[]], []
    while paths:
        path = paths.pop(0)
        help_text = run("strata", *path, "--help", env=env).stdout
        found.append((path, help_text))
        paths += [path + [sub] for sub in subcommands_in(help_text)]
    return found


def test_the_program_on_path_names_its_commit(prefix, env):
    assert run("which", "strata", env=env).stdout.strip() == str(prefix / "bin" / "strata")
    version = run("strata", "--version", env=env).stdout.strip()
    assert re.fullmatch(r"strata \d+\.\d+\.\d+ \(([0-9a-f]{12}(-dirty)?|unknown)\)", version)
    head = subprocess.run(["git", "-C", SOURCE, "rev-parse", "--short=12", "HEAD"],
                          capture_output=True, text=True)
    if head.returncode == 0:  # a source tree without .git prints "unknown"
        assert f"({head.stdout.strip()}" in version


def test_the_installed_program_makes_a_map_from_an_installed_scene(prefix, env, tmp_path):
    scene = prefix / "share" / "doc" / "strata" / "datasets" / "scenes" / "street.json"
    run("strata", "simulate", "--scene", scene, "--out", "seq", "--sensor", "vlp16",
        "--max-scans", 2, "--seed", 3, "--no-picture", env=env, cwd=tmp_path)
    run("strata", "integrate", "map", "--kitti", "seq", env=env, cwd=tmp_path)
    info = run("strata", "info", "map", "--json", env=env, cwd=tmp_path).stdout
    report = json.loads(info[info.index("{"):])
    assert report["occupied_voxels"] > 1000
    assert len(report["sessions"]) == 1


def test_nothing_installed_loads_from_the_build_tree(prefix):
    files = [prefix / "bin" / "strata", *sorted((prefix / "lib" / "strata").glob("*.so"))]
    if SITE:
        files += sorted((prefix / SITE / "strata").glob("*.so"))
    for file in files:
        dynamic = run("readelf", "-d", file).stdout
        loads = run("ldd", file).stdout
        assert "not found" not in loads, f"{file}:\n{loads}"
        for text in (dynamic, loads):
            assert str(BUILD) not in text and str(SOURCE) not in text, f"{file}:\n{text}"


def test_a_man_page_per_subcommand_lists_its_options(prefix, commands):
    man1 = prefix / "share" / "man" / "man1"
    expected = set()
    for path, help_text in commands:
        page = man1 / ("-".join(["strata", *path[:1]]) + ".1")
        expected.add(page.name)
        assert page.is_file(), f"strata {' '.join(path)}: no {page}"
        # -ww: every warning; one long line and no hyphenation, so option names stay whole.
        shown = run("groff", "-man", "-Tascii", "-P-cbou", "-ww", "-rLL=300n", "-rHY=0", page)
        assert shown.stderr == "", f"{page.name}: {shown.stderr}"
        for option in options_in(help_text):
            assert re.search(rf"(^|[\s,]){re.escape(option)}([\s,]|$)", shown.stdout, re.M), \
                f"{page.name} lacks strata {' '.join(path)} {option}"
    assert {p.name for p in man1.iterdir()} == expected


def test_the_bash_completion_offers_every_subcommand_and_option(prefix, commands):
    script = prefix / "share" / "bash-completion" / "completions" / "strata"
    loaded = run("bash", "-c", f"source '{script}' && complete -p strata").stdout
    assert loaded.strip() == "complete -o default -F _strata strata"
    # One shell asks for each command path's completions of "-" (its options) and of ""
    # (its subcommands), one line each.
    queries = [f"source '{script}'", "Ask() { COMPREPLY=(); COMP_WORDS=(\"$@\"); "
               "COMP_CWORD=$(($# - 1)); _strata; echo \"${COMPREPLY[*]}\"; }"]
    for path, _ in commands:
        queries += [f"Ask strata {' '.join(path)} -", f"Ask strata {' '.join(path)} ''"]
    answers = run("bash", "-c", "\n".join(queries)).stdout.split("\n")
    for i, (path, help_text) in enumerate(commands):
        words = " ".join(["strata", *path])
        assert sorted(answers[2 * i].split()) == sorted(options_in(help_text)), words
        assert sorted(answers[2 * i + 1].split()) == sorted(subcommands_in(help_text)), words


def test_the_docs_are_installed_with_their_links(prefix):
    doc = prefix / "share" / "doc" / "strata"
    for name in ["README.md", "docs/python.md", "docs/images/python_slant.png",
                 "datasets/README.md"]:
        assert (doc / name).is_file(), name
    # The README's links to the docs resolve where it is installed.
    for link in re.findall(r"\]\((docs/[^)#]+)", (doc / "README.md").read_text()):
        assert (doc / link).is_file(), link


def test_debians_python3_imports_the_installed_module(prefix, tmp_path):
    # Installed into /usr/local, the module is where Debian's python3 looks.
    path = run(PYTHON, "-c", "import sys; print('\\n'.join(sys.path))").stdout.split()
    assert f"/usr/local/{SITE}" in path, path
    code = ("import strata; print(strata.__file__); "
            "print(len(strata.VoxelMap(0.5).voxels([0, 0, 0], [1, 1, 1])['hits']))")
    done = run(PYTHON, "-c", code, cwd=tmp_path,
               env=dict(os.environ, PYTHONPATH=str(prefix / SITE)))
    assert done.stdout.splitlines() == [str(prefix / SITE / "strata" / "__init__.py"), "0"]
