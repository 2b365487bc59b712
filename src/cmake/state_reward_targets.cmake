# state_reward targets (filled by the state_reward area)
