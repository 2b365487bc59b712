"""The launch runner: every roslaunch that run and train start goes through Launch (a free
master port, the message key, the console log, the parent-death signal, SIGINT/SIGTERM), and
every command reads its console with node_deaths / last_fatal: a command whose nodes died
never reports success."""
import importlib.machinery
import os
import re
import signal
import socket
import subprocess
import sys
import threading
import time
import types

from palcas_cli import ROOT

ANSI = re.compile(r"\x1b\[[0-9;]*m")
# What a run shows of its console on the terminal (the rest is in console.log);
# $PALCAS_SHOW replaces it.
SHOWN = r"palcas bridge: (episode|SUMO)|FATAL|ERROR"
POLL_S = 0.2  # how often a waiting launch reads its console and looks at its helpers


# What roslaunch prints when its master's port was taken before it could bind it.
MASTER_PORT_TAKEN = "Address already in use"
# Starts of a launch whose master lost its port to another process, before giving up.
PORT_ATTEMPTS = 3


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def ros_env(port, log_dir=None):
    """The environment of a private master on PORT (its logs in LOG_DIR)."""
    env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:%d" % port, ROS_HOSTNAME="127.0.0.1")
    if log_dir:
        env["ROS_LOG_DIR"] = str(log_dir)
    return env


def message_key(folder):
    """<folder>/auth.key: the run's or training's random message key (palcas_common/README.md),
    made on first use by the launch package's scripts/message_key (the one that system.launch
    runs by default), loaded as a module: one implementation, no child process. Every node of
    the run reads it: RSUs sign advisories and submissions, the bridge and the server refuse
    the rest."""
    loader = importlib.machinery.SourceFileLoader("palcas_message_key",
                                                  os.path.join(ROOT, "launch", "scripts", "message_key"))
    module = types.ModuleType(loader.name)
    loader.exec_module(module)
    return module.make(folder)


def git_commit():
    try:
        return subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def read_text(path):
    try:
        with open(path, errors="replace") as f:
            return f.read()
    except OSError:
        return ""


def node_deaths(console_text, crashed_by=None):
    """Nodes of a roslaunch console that died for good: a non-zero exit that roslaunch did not
    follow with a restart (respawn), or three deaths (a crash loop); a node that died once and
    came back is not lost. 'name (exit code N[, died k times])', sorted by name.

    crashed_by: the name prefix of the node whose crash ends the launch (the bridge, whose SUMO
    can abort). A node that died in the same episode as that crash, after it, or just before it
    with its restart still pending, was not lost: the launch ended before roslaunch could
    restart it, and the next launch starts every node afresh. Episodes come from the bridge's
    progress lines ('palcas bridge: episode k/n')."""
    text = ANSI.sub("", console_text)
    events = []  # (position, kind, node, exit code); kind: death | restart | episode
    for m in re.finditer(r"\[([^\[\]\s]+)\] process has died \[pid \d+, exit code (-?\d+)", text):
        if m.group(2) != "0":
            events.append((m.start(), "death", m.group(1), m.group(2)))
    for m in re.finditer(r"\[([^\[\]\s]+)\] restarting process", text):
        events.append((m.start(), "restart", m.group(1), None))
    for m in re.finditer(r"palcas bridge: episode (\d+)/", text):
        events.append((m.start(), "episode", m.group(1), None))
    events.sort()
    crash = next((i for i, e in enumerate(events)
                  if crashed_by and e[1] == "death" and e[2].startswith(crashed_by)), None)
    episode_at, episode = [], None
    for e in events:
        episode = e[2] if e[1] == "episode" else episode
        episode_at.append(episode)
    deaths, restarts, codes, pending = {}, {}, {}, set()
    for i, (_, kind, node, code) in enumerate(events):
        if kind == "death":
            deaths[node] = deaths.get(node, 0) + 1
            codes[node] = code
            if crash is not None and node != events[crash][2] and (i > crash or episode_at[i] == episode_at[crash]):
                pending.add(node)
            else:
                pending.discard(node)
        elif kind == "restart":
            restarts[node] = restarts.get(node, 0) + 1
    lost = []
    for node in sorted(deaths):
        d, r = deaths[node], restarts.get(node, 0)
        if d >= 3 or (d > r and node not in pending):
            lost.append("%s (exit code %s%s)" % (node, codes[node], ", died %d times" % d if d > 1 else ""))
    return lost


def last_fatal(console_text):
    """The last FATAL/ERROR line or SUMO assertion, shortened."""
    lines = [line for line in ANSI.sub("", console_text).splitlines()
             if re.search(r"\[(FATAL|ERROR)\]|Assertion .* failed|Segmentation fault", line)]
    return lines[-1][:400] if lines else ""


def inprocess_refusals(console_text):
    """The in-process RSUs the bridge refused at start (their parameters, or their registration),
    sorted: a configuration error that every later episode would repeat, so a training stops on
    it as on a lost RSU node, where a SUMO crash costs one episode."""
    return sorted(set(re.findall(r"\[FATAL\].*?in-process RSU '([^']+)'", ANSI.sub("", console_text))))


def crash_reason(console_text):
    """Why a simulation ended early: its own error first (an RSU killed on the way is not why)."""
    text = ANSI.sub("", console_text)
    found = re.findall(r"(?:Assertion.*|Segmentation fault.*|\[FATAL\].*)", text)
    if found:
        return found[-1][:200]
    died = re.search(r"process has died.*", text)
    return died.group(0)[:200] if died else ""


class Interrupted(Exception):
    """The command was stopped by SIGINT or SIGTERM; every launch of it has stopped."""

    def __init__(self, name):
        super().__init__(name)
        self.signal = name
        self.status = 130 if name == "INT" else 143


_live = set()  # launches under way, for the signal handler and stop_all
_live_lock = threading.Lock()
_stopping = {"signal": None}


def interrupted():
    """INT or TERM once the command was told to stop, else None."""
    return _stopping["signal"]


def handle_signals():
    """SIGINT (Ctrl-C) or SIGTERM (a scheduler, kill) of the command: remembered, and SIGINT
    goes to every launch under way, which then stops its nodes (a training's checkpoint)."""
    def stop(signum, _frame):
        _stopping["signal"] = "INT" if signum == signal.SIGINT else "TERM"
        with _live_lock:
            launches = list(_live)
        for launch in launches:
            launch.interrupt()
    signal.signal(signal.SIGINT, stop)
    signal.signal(signal.SIGTERM, stop)


def stop_all(grace_s=30.0):
    """SIGINT to every launch under way, SIGKILL to what is left of them after grace_s: a
    command stopped from another thread (./palcas experiment) leaves no process behind."""
    _stopping["signal"] = _stopping["signal"] or "INT"
    with _live_lock:
        launches = list(_live)
    for launch in launches:
        launch.interrupt()
    deadline = time.time() + grace_s
    for launch in launches:
        launch.kill_after(deadline)


class Launch:
    """One roslaunch on a free master port, its console in a file (appended to with append),
    lines matching `show` (a regex, None = nothing) also written to `shown`, ANSI colours
    removed. roslaunch runs in its own process group with a parent-death signal: if this
    process is killed outright (SIGKILL, no handler runs), roslaunch still gets SIGINT and stops
    every node (test/faults/train_sigkill_test.sh). Success is judged by what the run writes,
    not by roslaunch's status."""

    def __init__(self, args, console, log_dir, append=False, show=None, shown=None, master_port=None):
        self.args, self.console, self.log_dir = list(args), str(console), str(log_dir)
        self.append, self.show = append, re.compile(show) if show else None
        self.shown = shown or sys.stdout
        # master_port: join the master another launch of this command started there (it waits
        # for it) instead of starting one of its own on a free port.
        self.master_port = master_port
        self.port, self.process, self._offset, self._partial = None, None, 0, ""
        self._start_offset = 0

    def start(self):
        if interrupted():  # the command was stopped before this launch: none starts
            raise Interrupted(interrupted())
        self.port = self.master_port or free_port()
        master = ["--wait"] if self.master_port else ["-p", str(self.port)]
        mode = "a" if self.append else "w"
        with open(self.console, mode) as console:
            self._offset = self._start_offset = console.tell()
            self.process = subprocess.Popen(
                # env --default-signal: a command started in the background by a non-interactive
                # shell (a CI runner, `./palcas test &`) passes SIGINT on ignored, and a launch
                # that starts with it ignored may never see the stop it carries.
                ["env", "--default-signal=INT", "setpriv", "--pdeathsig", "INT", "roslaunch"] + master
                + self.args,
                stdout=console, stderr=subprocess.STDOUT, env=ros_env(self.port, self.log_dir),
                start_new_session=True)
        with _live_lock:
            _live.add(self)
        if interrupted():  # stopped while it started
            self.interrupt()
        return self

    def lost_its_port(self):
        """True when this launch's master could not bind its port (another process took it
        between free_port() and roscore's bind): no node ran, so starting again is safe."""
        try:
            with open(self.console, errors="replace") as f:
                f.seek(self._start_offset)
                text = f.read()
        except OSError:
            return False
        return MASTER_PORT_TAKEN in text and "could not contact master" in text

    def wait(self, tick=None):
        """Waits for roslaunch to end, showing its console; tick() runs every POLL_S meanwhile
        (in the calling thread). Returns roslaunch's exit status; raises Interrupted if the
        command was stopped meanwhile."""
        try:
            while True:
                try:
                    status = self.process.wait(timeout=POLL_S)
                    break
                except subprocess.TimeoutExpired:
                    self._follow()
                    if tick:
                        tick()
        finally:
            with _live_lock:
                _live.discard(self)
        self._follow(final=True)
        if interrupted():
            raise Interrupted(interrupted())
        return status

    def running(self):
        return self.process is not None and self.process.poll() is None

    def interrupt(self):
        if self.running():
            try:
                self.process.send_signal(signal.SIGINT)
            except ProcessLookupError:
                pass

    def kill_after(self, deadline):
        try:
            self.process.wait(timeout=max(0.1, deadline - time.time()))
        except subprocess.TimeoutExpired:
            try:
                os.killpg(self.process.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass

    def _follow(self, final=False):
        if not self.show:
            return
        try:
            with open(self.console, errors="replace") as f:
                f.seek(self._offset)
                text = f.read()
                self._offset = f.tell()
        except OSError:
            return
        lines = (self._partial + text).split("\n")
        self._partial = "" if final else lines.pop()
        for line in lines:
            if line and self.show.search(line):
                self.shown.write(ANSI.sub("", line) + "\n")
        self.shown.flush()
