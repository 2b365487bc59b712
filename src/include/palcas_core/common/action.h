#pragma once
// The PDQN hybrid action of one CAV (paper, "Action Space"): a0 lane left, a1 lane
// right, a2 accelerate with a continuous parameter, a3 keep the current speed.
// palcas_msgs/Advisory mirrors these values as message constants; a test checks it.

#include <cstdint>
#include <string>

namespace palcas {

enum class Action : int { kLaneLeft = 0, kLaneRight = 1, kAccelerate = 2, kKeep = 3 };

constexpr int ACTION_COUNT = 4;
/// Continuous parameters per action: only kAccelerate carries one (acceleration, m/s^2).
constexpr int ACTION_PARAM_SIZE = 1;

/// Name used in logs, JSON and CSV ("lane_left", "lane_right", "accelerate", "keep").
std::string actionName(Action action);

/// True when `value` is one of the four action codes.
constexpr bool isValidActionCode(int value) { return value >= 0 && value < ACTION_COUNT; }

/// A set of actions, bit a for action code a: the valid-action mask of a state is the set of
/// actions a CAV may take in it.
using ActionMask = uint8_t;
constexpr ActionMask actionBit(Action action) {
  return static_cast<ActionMask>(1u << static_cast<int>(action));
}
constexpr ActionMask ALL_ACTIONS = (1u << ACTION_COUNT) - 1;
/// True for a mask of known actions that leaves at least one (a max over none is -inf).
constexpr bool isValidActionMask(int value) { return value > 0 && value <= ALL_ACTIONS; }

}  // namespace palcas
