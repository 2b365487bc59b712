#!/usr/bin/python3
"""Progress of a training run on one line: episode, sim time, mean reward, epsilon,
federation round, CR / DSR / MSR of the last finished episode, pace and time left.

Runs beside a training launch (./palcas train starts it):
    train_monitor.py --rsus rsu_0 rsu_1 rsu_2 --episodes N --duration S [--period 10]
        [--first-episode K --total-episodes T]

A training that draws its traffic per episode runs one launch (and one monitor) per episode:
--first-episode and --total-episodes make the line count against the whole training, and
the time left cover every episode still to run, at this launch's pace.
"""
import argparse
import math
import time

import rospy
from palcas_msgs.msg import EpisodeMetrics, RsuStatus


def progress(first_episode, episode, total_episodes, duration_s, sim_s, wall_s):
    """(simulated seconds done in this launch, wall seconds left for the whole training):
    the episodes from `episode` (0-based, running at `sim_s`) to `total_episodes`, at the pace
    of this launch, which started at `first_episode` `wall_s` ago. NaN before any progress."""
    done = (episode - first_episode) * duration_s + sim_s
    to_do = (total_episodes - first_episode) * duration_s - done
    return done, (to_do * wall_s / done if done > 0 and wall_s > 0 else float("nan"))


def fmt(value, pattern="{:.2f}"):
    return "n/a" if value is None or (isinstance(value, float) and math.isnan(value)) else pattern.format(value)


class Monitor:
    def __init__(self, args):
        self.args = args
        self.metrics = None
        self.last_episode = None  # metrics of the last finished episode
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
                              m.sim_seconds if m else 0.0, wall)
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
