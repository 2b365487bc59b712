#!/usr/bin/python3
"""Test: every package.xml declares what its package builds against, includes and launches.

- every `find_package(catkin REQUIRED COMPONENTS ...)` component and every other
  find_package (by its rosdep key) is a build dependency (<depend> or <build_depend>);
- every ROS package a C++ file of the package includes (`#include <pkg/...>`) is a build
  dependency;
- every `pkg="..."` a launch file starts is a run dependency (<depend> or <exec_depend>) of
  the package holding that launch file; test launch files' packages are test dependencies;
- palcas_core's CMake extras export the flags it was built with;
- a plain `catkin_make` at the repository root stops and names the command that works.
"""
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "test" / "tools"))
from junit_runner import run_as_junit  # noqa: E402

PACKAGE_DIRS = ["src", "palcas_msgs", "palcas_common", "palcas_rsu", "palcas_fedserver",
                "palcas_sumo_bridge", "launch", "config", "test"]
# find_package names that are not ROS package names -> their rosdep key.
ROSDEP = {"Eigen3": "eigen", "OpenSSL": "libssl-dev", "nlohmann_json": "nlohmann-json3-dev",
          "GTest": "gtest", "rostest": "rostest", "catkin": None, "OpenMP": None}
# Include prefixes that are no ROS package: the C++ and system libraries, or inside another.
NOT_PACKAGES = {"sys", "openssl", "nlohmann", "gtest", "ros", "xmlrpcpp", "libsumo", "Eigen",
                "benchmark", "boost", "gmock"}
# A header folder that belongs to another package.
INCLUDE_PACKAGE = {"libsumo": "sumo", "nlohmann": "nlohmann-json3-dev", "openssl": "libssl-dev",
                   "ros": "roscpp", "xmlrpcpp": "roscpp"}


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
