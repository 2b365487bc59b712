# state_reward tests (filled by the state_reward area)
