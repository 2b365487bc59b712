#!/usr/bin/python3
"""Test: every package.xml declares what its package builds against, includes and launches.

- every `find_package(catkin REQUIRED COMPONENTS ...)` component and every other
  find_package (by its rosdep key) is a build dependency (<depend> or <build_depend>);
- every ROS package a C++ file of the package includes (`#include <pkg/...>`) is a build
  dependency;
- every `pkg="..."` a launch file starts is a run dependency (<depend> or <exec_depend>) of
  the package holding that launch file; test launch files' packages are test dependencies;
- every third-party module a package's Python imports is one of its dependencies (tools/,
  not a catkin package, counts as palcas_launch's: its commands start those launches);
- catkin_lint reports no error or warning on any package;
- every rosdep key a package.xml names resolves: a package of this repository, or a key of
  rosdep/keys.yaml (Debian's rules, rosdistro's, rosdep/palcas.yaml's), checked against
  Debian's rules file where python3-rosdep2 is installed; the repository's LICENSE is the
  license every package.xml names;
- palcas_core's CMake extras export the flags it was built with;
- a plain `catkin_make` at the repository root stops and names the command that works.
"""
import ast
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET

import yaml

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "test" / "tools"))
from junit_runner import run_as_junit  # noqa: E402

PACKAGE_DIRS = ["src", "palcas_msgs", "palcas_common", "palcas_rsu", "palcas_fedserver",
                "palcas_sumo_bridge", "launch", "config", "policies", "test"]
# find_package names that are not ROS package names -> their rosdep key.
ROSDEP = {"Eigen3": "eigen", "OpenSSL": "libssl-dev", "nlohmann_json": "nlohmann-json-dev",
          "GTest": "gtest", "rostest": "rostest", "catkin": None, "OpenMP": None, "pybind11": "pybind11-dev",
          "Python3": "python3-dev"}
# Include prefixes that are no ROS package: the C++ and system libraries, or inside another.
NOT_PACKAGES = {"sys", "netinet", "openssl", "nlohmann", "gtest", "ros", "xmlrpcpp", "libsumo", "Eigen",
                "benchmark", "boost", "gmock"}
# A header folder that belongs to another package.
INCLUDE_PACKAGE = {"libsumo": "sumo", "nlohmann": "nlohmann-json-dev", "openssl": "libssl-dev", "pybind11": "pybind11-dev",
                   "ros": "roscpp", "xmlrpcpp": "roscpp"}


# Every tag of package format 2 that names a rosdep key.
DEPEND_TAGS = ("depend", "build_depend", "build_export_depend", "buildtool_depend", "buildtool_export_depend",
               "exec_depend", "test_depend", "doc_depend")
# The rules rosdep resolves keys with: Debian's own (python3-rosdep2), and the keys of this
# repository's package.xml files resolved by rosdistro's and rosdep/palcas.yaml's (committed).
DEBIAN_RULES = pathlib.Path("/usr/share/python3-rosdep2/debian.yaml")
KEYS_FILE = ROOT / "rosdep" / "keys.yaml"
# Python modules whose rosdep key is not their name (a ROS package's module is its name).
MODULE_KEYS = {"yaml": "python3-yaml", "numpy": "python3-numpy", "matplotlib": "python3-matplotlib",
               "PIL": "python3-pil", "scipy": "python3-scipy", "rospkg": "python3-rospkg"}
# Python that is no package's own: whose dependencies it counts as (run or test).
PYTHON_OWNERS = {"tools": ("launch", "run")}


def manifest(folder):
    root = ET.parse(ROOT / folder / "package.xml").getroot()
    deps = {}
    for tag in ("depend", "build_depend", "exec_depend", "test_depend", "buildtool_depend"):
        deps[tag] = {e.text.strip() for e in root.findall(tag)}
    build = deps["depend"] | deps["build_depend"] | deps["buildtool_depend"]
    run = deps["depend"] | deps["exec_depend"]
    return root.findtext("name").strip(), build, run, deps["test_depend"] | build | run


def cmake_text(folder):
    files = [ROOT / folder / "CMakeLists.txt"] + sorted((ROOT / folder).rglob("*.cmake"))
    return "\n".join(f.read_text() for f in files if f.exists() and "build" not in f.parts)


def sources(folder):
    for ext in ("*.cpp", "*.h"):
        for f in (ROOT / folder).rglob(ext):
            if f.name != "no_ros_headers_test.cpp":  # names ROS headers to prove none is used
                yield f


def all_keys(folder):
    """{key: [tags]} of every dependency a package.xml names."""
    root = ET.parse(ROOT / folder / "package.xml").getroot()
    keys = {}
    for tag in DEPEND_TAGS:
        for e in root.findall(tag):
            keys.setdefault(e.text.strip(), []).append(tag)
    return keys


def package_folders():
    """Every folder of the repository with a package.xml (the catkin source space)."""
    return sorted(p.parent.name for p in ROOT.glob("*/package.xml"))


def python_imports(path):
    """Top-level modules a Python file imports, except those imported only under a `try`
    that catches ImportError (optional ones)."""
    tree = ast.parse(path.read_text())
    optional = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Try) and any(
                h.type is None or "ImportError" in ast.dump(h.type) or "Exception" in ast.dump(h.type)
                for h in node.handlers):
            for inner in node.body:
                for n in ast.walk(inner):
                    if isinstance(n, (ast.Import, ast.ImportFrom)):
                        optional.add(id(n))
    found = set()
    for n in ast.walk(tree):
        if id(n) in optional:
            continue
        if isinstance(n, ast.Import):
            found |= {a.name.split(".")[0] for a in n.names}
        elif isinstance(n, ast.ImportFrom) and n.level == 0 and n.module:
            found.add(n.module.split(".")[0])
    return found


def local_modules():
    """Modules of this repository (a .py file or a package folder): imported from a path."""
    files = [f for f in ROOT.rglob("*.py") if not {"build", "devel", "install", ".git"} & set(
        f.relative_to(ROOT).parts)]
    return {f.stem for f in files} | {f.parent.name for f in files if f.name == "__init__.py"}


class PackageDepsTest(unittest.TestCase):
    def test_find_package_components_are_dependencies(self):
        for folder in PACKAGE_DIRS:
            name, build, _, everything = manifest(folder)
            text = cmake_text(folder)
            with self.subTest(package=name):
                missing = []
                for comps in re.findall(r"find_package\(\s*catkin\s+REQUIRED\s+COMPONENTS([^)]*)\)", text):
                    missing += [c for c in comps.split() if c not in build]
                for pkg in re.findall(r"find_package\(\s*(\w+)", text):
                    key = ROSDEP.get(pkg, pkg)
                    if key and key not in everything:
                        missing.append("%s (find_package %s)" % (key, pkg))
                self.assertEqual(missing, [], "%s/package.xml lacks build dependencies" % folder)

    def test_included_packages_are_dependencies(self):
        names = {manifest(f)[0] for f in PACKAGE_DIRS}
        for folder in PACKAGE_DIRS:
            name, build, _, everything = manifest(folder)
            with self.subTest(package=name):
                missing = set()
                for f in sources(folder):
                    for inc in re.findall(r"#include <([A-Za-z0-9_]+)/", f.read_text()):
                        pkg = INCLUDE_PACKAGE.get(inc, None if inc in NOT_PACKAGES else inc)
                        if pkg is None or pkg == name:
                            continue
                        deps = everything if "/test/" in str(f) else build
                        if pkg not in deps and (pkg in names or pkg not in NOT_PACKAGES):
                            missing.add("%s (%s)" % (pkg, f.relative_to(ROOT)))
                self.assertEqual(sorted(missing), [], "%s/package.xml lacks what its code includes" % folder)

    def test_launched_packages_are_run_dependencies(self):
        for folder in PACKAGE_DIRS:
            name, _, run, everything = manifest(folder)
            with self.subTest(package=name):
                missing = set()
                for f in (ROOT / folder).rglob("*.launch"):
                    for pkg in re.findall(r'<node[^>]*pkg="([^"]+)"', f.read_text()):
                        if pkg != name and pkg not in run:
                            missing.add("%s (%s)" % (pkg, f.relative_to(ROOT)))
                for f in (ROOT / folder).rglob("*.test"):
                    for pkg in re.findall(r'<(?:node|test)[^>]*pkg="([^"]+)"', f.read_text()):
                        if pkg != name and pkg not in everything:
                            missing.add("%s (%s)" % (pkg, f.relative_to(ROOT)))
                self.assertEqual(sorted(missing), [], "%s/package.xml lacks what it launches" % folder)

    def test_python_imports_are_dependencies(self):
        local, std = local_modules(), set(sys.stdlib_module_names)
        owners = {f: (f, None) for f in package_folders()}
        owners.update(PYTHON_OWNERS)
        for folder, (package_folder, kind) in sorted(owners.items()):
            name, _, run, everything = manifest(package_folder)
            with self.subTest(folder=folder, package=name):
                missing = set()
                for f in sorted((ROOT / folder).rglob("*.py")):
                    rel = f.relative_to(ROOT / folder)
                    # A package's tests (and the palcas_tests package) may use test dependencies.
                    testing = kind != "run" and (folder == "test" or "test" in rel.parts)
                    for module in python_imports(f) - std - local:
                        key = MODULE_KEYS.get(module, module)
                        if key != name and key not in (everything if testing else run):
                            missing.add("%s (%s: import %s)" % (key, f.relative_to(ROOT), module))
                self.assertEqual(sorted(missing), [], "%s/package.xml lacks what its Python imports" % package_folder)

    def test_every_rosdep_key_resolves(self):
        names = {manifest(f)[0] for f in package_folders()}
        listed = yaml.safe_load(KEYS_FILE.read_text())
        known = {k: v for section in listed.values() for k, v in section.items()}
        used = set()
        for folder in package_folders():
            used |= set(all_keys(folder)) - names
            with self.subTest(package=folder):
                unknown = sorted(k for k in all_keys(folder) if k not in names and k not in known)
                self.assertEqual(unknown, [], "%s/package.xml names rosdep keys rosdep cannot resolve (not in "
                                 "rosdep/keys.yaml; a Debian package name is not always its key)" % folder)
        self.assertEqual(sorted(set(known) - used), [], "rosdep/keys.yaml lists keys no package.xml names")
        own = yaml.safe_load((ROOT / "rosdep" / "palcas.yaml").read_text())
        self.assertEqual({k: v["debian"] for k, v in own.items()}, listed["palcas"],
                         "rosdep/keys.yaml's palcas keys are not rosdep/palcas.yaml's rules")

    def test_debians_rules_resolve_the_listed_keys_alike(self):
        if not DEBIAN_RULES.exists():
            self.skipTest("python3-rosdep2 is not installed: rosdep/keys.yaml stands for its rules")
        rules = yaml.safe_load(DEBIAN_RULES.read_text())
        listed = yaml.safe_load(KEYS_FILE.read_text())
        for key, packages in listed["debian_rosdep"].items():
            self.assertIn(key, rules, "%s: no key of %s" % (key, DEBIAN_RULES))
            self.assertEqual(rules[key].get("debian"), packages, "%s resolves otherwise in %s" % (key, DEBIAN_RULES))
        for section in ("rosdistro", "palcas"):
            for key in listed[section]:
                # Debian's rules come first in rosdep's sources: they would decide this key.
                self.assertNotIn(key, rules, "%s is a key of %s, not of %s" % (key, DEBIAN_RULES, section))

    def test_palcas_installs_what_the_keys_resolve_to(self):
        # ./palcas installs each Debian package some key resolves to, or a tool around the
        # build (TOOLS); a package nothing names (as libtf2-geometry-msgs-dev was) is refused.
        tools = {"build-essential": "compilers", "cmake": "catkin_make", "ros-core-dev": "roscore, roslaunch",
                 "rosbash": "rosrun"}
        script = (ROOT / "palcas").read_text()
        installed = re.search(r"^DEBIAN_PACKAGES=\(([^)]*)\)", script, re.M).group(1).split()
        listed = yaml.safe_load(KEYS_FILE.read_text())
        resolved = {p for section in listed.values() for packages in section.values() for p in packages}
        self.assertEqual(sorted(p for p in installed if p not in resolved and p not in tools), [],
                         "./palcas installs Debian packages no rosdep key of a package.xml resolves to")

    def test_catkin_lint_finds_no_error_or_warning(self):
        # catkin_lint (Debian's catkin-lint) checks each package's CMakeLists.txt against its
        # package.xml the way catkin uses them. --strict fails on its errors and warnings alike;
        # a false positive is suppressed in the CMakeLists.txt by a "#catkin_lint: ignore_once"
        # pragma with the reason beside it. Its notices (-W2) are tolerated: style only
        # (${PROJECT_NAME} over the name, sorted lists, and launch/, policies/ and test/ holding
        # packages named otherwise, which the repository's layout wants). --offline: no rosdep
        # download (the rosdep keys are checked above, against rosdep/keys.yaml).
        if not pathlib.Path("/usr/bin/catkin_lint").exists():
            self.fail("catkin_lint is not installed: ./palcas setup installs catkin-lint")
        folders = [str(ROOT / f) for f in package_folders()]
        r = subprocess.run(["/usr/bin/catkin_lint", "--offline", "--strict", "-W1", "--color", "never"] + folders,
                           capture_output=True, text=True, timeout=300)
        self.assertEqual(r.returncode, 0, "catkin_lint:\n" + r.stdout + r.stderr)
        self.assertIn("checked %d packages and found 0 problems" % len(folders), r.stderr + r.stdout)

    def test_the_license_every_package_names_is_the_repositorys(self):
        text = (ROOT / "LICENSE").read_text()
        self.assertTrue(text.startswith("BSD 3-Clause License"), "LICENSE is not the BSD 3-Clause text")
        self.assertIn("Copyright (c) 2026, the PALCAS authors", text)
        for folder in package_folders():
            with self.subTest(package=folder):
                root = ET.parse(ROOT / folder / "package.xml").getroot()
                self.assertEqual([e.text.strip() for e in root.findall("license")], ["BSD-3-Clause"])

    def test_palcas_core_exports_its_flags(self):
        # A package built against palcas_core's headers elsewhere (an install space, another
        # workspace) gets C++17 and -march from its CMake config, not only from the target.
        extras = ROOT / "devel/share/palcas_core/cmake/palcas_core-extras.cmake"
        if not extras.exists():
            self.skipTest("not built: ./palcas build first")
        text = extras.read_text()
        self.assertIn("CMAKE_CXX_STANDARD 17", text)
        self.assertIn("add_compile_options(${palcas_core_ABI_OPTIONS}", text)
        cache = (ROOT / "build/CMakeCache.txt").read_text()
        if "PALCAS_NATIVE_ARCH:BOOL=ON" in cache:
            self.assertIn('palcas_core_ABI_OPTIONS "-march=native"', text)

    def test_plain_catkin_make_at_the_root_says_what_to_run(self):
        # catkin_make's default source space is ./src, which here is the palcas_core package:
        # it must stop at configure time naming the command that builds the workspace.
        files = subprocess.run(["git", "-C", str(ROOT), "ls-files", "src", "CMakeLists.txt", "palcas"],
                               capture_output=True, text=True, check=True).stdout.split()
        with tempfile.TemporaryDirectory() as clone:
            for f in files:
                (pathlib.Path(clone) / f).parent.mkdir(parents=True, exist_ok=True)
                (pathlib.Path(clone) / f).write_bytes((ROOT / f).read_bytes())
            env = dict(os.environ, PATH="/usr/bin:/bin", PWD=clone)
            r = subprocess.run(["catkin_make"], cwd=clone, capture_output=True, text=True, timeout=300, env=env)
        self.assertNotEqual(r.returncode, 0, "a plain catkin_make at the root built src/ alone")
        self.assertIn("catkin_make --source . --build build", r.stdout + r.stderr)


if __name__ == "__main__":
    run_as_junit(sys.modules[__name__], "package_deps")
