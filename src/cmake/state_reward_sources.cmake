# state_reward sources (filled by the state_reward area)
