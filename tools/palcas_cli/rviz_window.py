"""./palcas run --rviz: rviz runs outside roslaunch, which stops every node of its launch when
the bridge ends, so that the last arm's window stays for the user to close. It opens the view
the bridge writes for its road (<arm folder>/palcas.rviz), on that launch's master."""
import os
import signal
import subprocess

from palcas_cli import launch


class RvizWindow:
    def __init__(self, console):
        self.console = console
        self.process = None  # rviz, once the bridge framed the road
        self.pending = None  # (folder, port) of a launch whose view rviz waits for
        self.log = ""

    def watch(self, folder, port):
        """Open rviz on FOLDER's view once the bridge writes it (poll() looks)."""
        self.pending = (folder, port)
        self.log = os.path.join(folder, "rviz.log")

    def poll(self):
        """Called from the thread that waits for the launch: rviz's parent-death signal follows
        the thread that starts it."""
        if not self.pending or not os.path.isfile(os.path.join(self.pending[0], "palcas.rviz")):
            return
        folder, port = self.pending
        self.pending = None
        with open(self.log, "w") as log:
            self.process = subprocess.Popen(
                ["setpriv", "--pdeathsig", "TERM", "rviz", "-d", os.path.join(folder, "palcas.rviz"),
                 "__name:=palcas_rviz"], stdout=log, stderr=subprocess.STDOUT,
                env=launch.ros_env(port, os.path.join(folder, "ros_log")))

    def close(self):
        """The previous arm's window (each run is shown on its own master), or on the way out."""
        self.pending = None
        if not self.process:
            return
        self.process.send_signal(signal.SIGINT)
        try:
            self.process.wait(timeout=5)
        except subprocess.TimeoutExpired:  # rviz ignored SIGINT for 5 s
            self.process.kill()
            self.process.wait()
        self.process = None

    def wait_until_closed(self):
        """The run is over: rviz stays until the user closes it."""
        self.pending = None
        if not self.process:
            return
        if self.process.poll() is not None:
            self.console.log("rviz is not running: closed, or it could not start (no display?); see %s" % self.log)
        else:
            self.console.log("the run is over; rviz stays open until you close its window (or press Ctrl-C)")
            while self.process.poll() is None and not launch.interrupted():
                try:
                    self.process.wait(timeout=launch.POLL_S)
                except subprocess.TimeoutExpired:
                    pass
            if launch.interrupted():
                self.close()
                raise launch.Interrupted(launch.interrupted())
        self.process = None
