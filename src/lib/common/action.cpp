#include "palcas_core/common/action.h"

namespace palcas {

std::string actionName(Action action) {
  switch (action) {
    case Action::kLaneLeft: return "lane_left";
    case Action::kLaneRight: return "lane_right";
    case Action::kAccelerate: return "accelerate";
    case Action::kKeep: return "keep";
  }
  return "unknown";
}

}  // namespace palcas
