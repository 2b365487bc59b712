#!/usr/bin/python3
"""Test: every repository file or folder a README or `./palcas help` names exists.

A path is a backticked token (or, in the help text, a word) that starts with one of the
repository's top-level folders or ends in a file extension the project uses, and holds no
placeholder (<...>, *, $, {...}, ...). It resolves against the repository root, or against the
folder of the README that names it, or is the tail of a tracked path (an include path such
as `palcas_sim/road_layout.h`, a policy's `default/model.palcas`); a ROS package name stands
for its folder (`palcas_config/` is config/) and `palcas_msgs/Advisory` for its .msg. Paths
under build/, devel/, results/ and run folders are made by running things and are not checked.
"""
import pathlib
import re
import subprocess
import sys
import unittest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "test" / "tools"))
from junit_runner import run_as_junit  # noqa: E402

TOP = ("config/", "launch/", "tools/", "test/", "src/", "docs/", "palcas_msgs/", "palcas_rsu/",
       "palcas_fedserver/", "palcas_sumo_bridge/", "palcas_common/", "policies/")
EXT = re.compile(r"\.(md|yaml|yml|launch|test|py|sh|cpp|h|msg|srv|rviz|xml|cmake|txt|palcas|csv|json|png)$")
GENERATED = ("build/", "devel/", "results/", "/tmp/", "install/", "~", "figures/", "out_dir/", "dir/")
PLACEHOLDER = re.compile(r"[<>*${}…]|\.\.\.|\bDIR\b|\bFILE\b|\bBAG\b")
# ROS package names whose folder has another name.
PACKAGE_DIRS = {"palcas_config/": "config/", "palcas_tests/": "test/", "palcas_launch/": "launch/",
                "palcas_core/": "src/", "palcas_policies/": "policies/"}


def tracked():
    """Every tracked file and the folders that hold them, relative to the root."""
    files = subprocess.run(["git", "-C", str(ROOT), "ls-files"], capture_output=True, text=True,
                           check=True).stdout.split()
    paths = set(files)
    for f in files:
        parts = f.split("/")
        paths.update("/".join(parts[:i]) for i in range(1, len(parts)))
    return paths


TRACKED = tracked()


def exists(path, base):
    if (ROOT / path).exists() or (base / path).exists():
        return True
    for package, folder in PACKAGE_DIRS.items():
        if path.startswith(package) and (ROOT / (folder + path[len(package):])).exists():
            return True
    if path.startswith("palcas_msgs/") and path.count("/") == 1:
        name = path.split("/")[1]
        return (ROOT / "palcas_msgs/msg" / (name + ".msg")).exists() or \
            (ROOT / "palcas_msgs/srv" / (name + ".srv")).exists()
    return any(t == path or t.endswith("/" + path) for t in TRACKED)


def candidates(text):
    for token in re.findall(r"`([^`\n]+)`", text):
        token = token.strip()
        if " " in token or "=" in token or token.startswith("-"):
            continue
        yield token


def is_repo_path(token):
    if token.startswith(GENERATED) or PLACEHOLDER.search(token) or "://" in token:
        return False
    return token.startswith(TOP) or ("/" in token and EXT.search(token) is not None)


def readmes():
    skip = {"build", "devel", "results", ".git", "node_modules"}
    for path in sorted(ROOT.rglob("*.md")):
        if not skip.intersection(path.relative_to(ROOT).parts):
            yield path


class DocPathsTest(unittest.TestCase):
    def check(self, source, tokens, base):
        missing = []
        for token in tokens:
            path = token.rstrip("/.,:;)")
            if not is_repo_path(path):
                continue
            if not exists(path, base):
                missing.append(path)
        self.assertEqual(missing, [], "%s names paths that do not exist" % source)

    def test_readmes_name_existing_paths(self):
        checked = 0
        for readme in readmes():
            with self.subTest(readme=str(readme.relative_to(ROOT))):
                self.check(readme.relative_to(ROOT), candidates(readme.read_text()), readme.parent)
                checked += 1
        self.assertGreater(checked, 5)

    def test_help_names_existing_paths(self):
        out = subprocess.run([str(ROOT / "palcas"), "help"], capture_output=True, text=True, timeout=60,
                             env={"PATH": "/usr/bin:/bin"}).stdout
        self.assertIn("usage: ./palcas", out)
        words = re.findall(r"[A-Za-z0-9_./-]+", out)
        self.check("./palcas help", words, ROOT)

    def test_a_missing_path_is_caught(self):
        # The check itself must be able to fail.
        with self.assertRaises(AssertionError):
            self.check("a made-up README", ["config/training/comfort_tuned_cavs.yaml"], ROOT)


if __name__ == "__main__":
    run_as_junit(sys.modules[__name__], "doc_paths")
