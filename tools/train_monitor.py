#!/usr/bin/python3
"""Progress of a training run on one line: episode, sim time, mean reward, epsilon,
federation round, CR / DSR / MSR of the last finished episode, pace and time left.

Runs beside a training launch (./palcas train starts it):
    train_monitor.py --rsus rsu_0 rsu_1 rsu_2 --episodes N --duration S [--period 10]
        [--first-episode K --total-episodes T --episodes-csv FILE]

A training that draws its traffic per episode runs one launch (and one monitor) per episode:
--first-episode and --total-episodes make the line count against the whole training, and
--episodes-csv (the training's episodes.csv) gives the episodes finished before this launch:
the last one's CR / DSR / MSR until this launch finishes one, and their pace, so that the time
left is at the whole training's pace, not only at the current episode's (its demand sets it).
"""
import argparse
import csv
import math
import time
import types

import rospy
from palcas_msgs.msg import EpisodeMetrics, RsuStatus


def progress(first_episode, episode, total_episodes, duration_s, sim_s, wall_s, before=(0.0, 0.0)):
    """(simulated seconds done in this launch, wall seconds left for the whole training):
    the episodes from `episode` (0-based, running at `sim_s`) to `total_episodes`, at the pace
    of this launch, which started at `first_episode` `wall_s` ago, and of the episodes finished
    before it, `before` = (their simulated seconds, their wall seconds). NaN before any progress."""
    done = (episode - first_episode) * duration_s + sim_s
    to_do = (total_episodes - first_episode) * duration_s - done
    sim_all, wall_all = before[0] + done, before[1] + wall_s
    return done, (to_do * wall_all / sim_all if sim_all > 0 and wall_all > 0 else float("nan"))


def finished_before(episodes_csv):
    """(last finished episode's metrics or None, (simulated s, wall s) of all finished ones)
    from a training's episodes.csv; no file yet = nothing finished."""
    try:
        with open(episodes_csv) as f:
            rows = list(csv.DictReader(f))
    except OSError:
        return None, (0.0, 0.0)
    if not rows:
        return None, (0.0, 0.0)
    last = types.SimpleNamespace(**{k: float(rows[-1][k]) for k in ("collision_rate_pct", "dsr_pct", "msr_pct")})
    return last, (sum(float(r["sim_seconds"]) for r in rows), sum(float(r["wall_seconds"]) for r in rows))


def fmt(value, pattern="{:.2f}"):
    return "n/a" if value is None or (isinstance(value, float) and math.isnan(value)) else pattern.format(value)


class Monitor:
    def __init__(self, args):
        self.args = args
        self.metrics = None
        # metrics of the last finished episode, and the pace of those before this launch
        self.last_episode, self.before = finished_before(args.episodes_csv) if args.episodes_csv else (None, (0.0, 0.0))
        self.status = {}
        self.episode = args.first_episode
        self.start = time.monotonic()
        rospy.Subscriber("/episode_metrics", EpisodeMetrics, self.on_metrics, queue_size=10)
        for rsu in args.rsus:
            rospy.Subscriber("/%s/rsu_status" % rsu, RsuStatus, self.on_status, queue_size=10)

    def on_metrics(self, msg):
        if self.metrics is not None and msg.sim_seconds + 1e-6 < self.metrics.sim_seconds:
            self.last_episode = self.metrics  # the bridge started the next episode
            self.episode += 1
        self.metrics = msg

    def on_status(self, msg):
        self.status[msg.rsu_id] = msg

    def total_episodes(self):
        own = self.args.first_episode + self.args.episodes
        return max(own, self.args.total_episodes or 0)

    def line(self):
        m = self.metrics
        rewards = [s.mean_reward for s in self.status.values() if not math.isnan(s.mean_reward)]
        reward = sum(rewards) / len(rewards) if rewards else None
        eps = [s.epsilon for s in self.status.values()]
        rounds = [s.federation_round for s in self.status.values()]
        last = self.last_episode
        total_episodes = self.total_episodes()
        wall = time.monotonic() - self.start
        done, left = progress(self.args.first_episode, self.episode, total_episodes, self.args.duration,
                              m.sim_seconds if m else 0.0, wall, self.before)
        return ("episode %d/%d | t %5.0f/%.0f s | reward %s | eps %s | fed round %s | last ep CR %s%% DSR %s%% "
                "MSR %s%% | speed %s m/s | %.1fx | ~%s min left" % (
                    self.episode + 1, total_episodes,
                    m.sim_seconds if m else 0.0, self.args.duration, fmt(reward, "{:.3f}"),
                    fmt(sum(eps) / len(eps) if eps else None, "{:.3f}"), max(rounds) if rounds else "n/a",
                    fmt(last.collision_rate_pct if last else None, "{:.1f}"),
                    fmt(last.dsr_pct if last else None, "{:.1f}"), fmt(last.msr_pct if last else None, "{:.1f}"),
                    fmt(m.efficiency_all_mps if m else None), done / wall if wall > 0 else 0.0,
                    fmt(left / 60.0, "{:.0f}")))


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--rsus", nargs="+", required=True)
    parser.add_argument("--episodes", type=int, required=True)
    parser.add_argument("--first-episode", type=int, default=0)
    parser.add_argument("--total-episodes", type=int, default=0,
                        help="episodes of the whole training (default: first episode + --episodes)")
    parser.add_argument("--duration", type=float, required=True)
    parser.add_argument("--episodes-csv", default="",
                        help="the training's episodes.csv: episodes finished before this launch")
    parser.add_argument("--period", type=float, default=10.0, help="wall seconds between lines")
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node("palcas_train_monitor", disable_signals=False)
    monitor = Monitor(args)
    while not rospy.is_shutdown():
        time.sleep(args.period)
        if monitor.metrics is not None:
            print(monitor.line(), flush=True)


if __name__ == "__main__":
    main()
