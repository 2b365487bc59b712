#!/usr/bin/python3
"""The suite's /diagnostics as a table on the terminal: one row per status (the bridge's
lockstep, simulation and advice guard, each RSU's decisions, the federation server), its level,
message and chosen values, the newest report of each. Debian 12's ROS has neither
rqt_robot_monitor nor rosdiagnostic; this needs only rospy.

    tools/diagnostics_view.py [--once] [--keys K1,K2]   (ROS_MASTER_URI of the run)

--once prints the first full table (every status heard within 3 s) and exits; without it the
table is redrawn every 2 s until Ctrl-C. --keys shows only those values (default: all)."""
import argparse
import sys
import time

LEVELS = {0: "OK", 1: "WARN", 2: "ERROR", 3: "STALE"}


def table(statuses, keys=None):
    """statuses: {name: (level, message, [(key, value), ...])} -> the table's text, rows by name."""
    if not statuses:
        return "no /diagnostics heard yet\n"
    width = max(len(n) for n in statuses)
    lines = []
    for name in sorted(statuses):
        level, message, values = statuses[name]
        shown = [(k, v) for k, v in values if keys is None or k in keys]
        lines.append("%-*s  %-5s  %s" % (width, name, LEVELS.get(level, str(level)), message))
        lines += ["%-*s    %s: %s" % (width, "", k, v) for k, v in shown]
    return "\n".join(lines) + "\n"


def main(argv=None):
    p = argparse.ArgumentParser(prog="diagnostics_view.py", description=__doc__.split("\n\n")[0])
    p.add_argument("--once", action="store_true", help="print one table and exit")
    p.add_argument("--keys", default="", help="comma-separated value keys to show (default: all)")
    args = p.parse_args(argv)
    keys = set(k.strip() for k in args.keys.split(",") if k.strip()) or None
    import rospy  # here, so that table() is testable without ROS
    from diagnostic_msgs.msg import DiagnosticArray
    statuses = {}

    def on_array(msg):
        for s in msg.status:
            statuses[s.name] = (s.level if isinstance(s.level, int) else ord(s.level), s.message,
                                [(kv.key, kv.value) for kv in s.values])

    rospy.init_node("palcas_diagnostics_view", anonymous=True, disable_signals=False)
    rospy.Subscriber("/diagnostics", DiagnosticArray, on_array, queue_size=50)
    if args.once:
        time.sleep(3.0)  # wall time: a run's /clock may be paused or far ahead
        sys.stdout.write(table(dict(statuses), keys))
        return 0
    while not rospy.is_shutdown():
        sys.stdout.write("\033[2J\033[H" + time.strftime("%H:%M:%S ") + "/diagnostics\n" + table(dict(statuses), keys))
        sys.stdout.flush()
        time.sleep(2.0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
