#include "palcas_core/learning/pdqn_agent.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace palcas {

namespace {

nn::AdamWConfig adamConfig(const PdqnConfig& c) {
  return {c.learning_rate, c.adam_beta1, c.adam_beta2, c.adam_eps, c.weight_decay};
}

const PdqnConfig& validated(const PdqnConfig& c) {
  c.validate();
  return c;
}

nn::MlpSpec mlpSpec(const PdqnConfig& c, nn::Index in, nn::Index out, nn::OutputActivation act) {
  nn::MlpSpec spec;
  spec.input_size = in;
  spec.hidden_sizes.assign(c.hidden_sizes.begin(), c.hidden_sizes.end());
  spec.output_size = out;
  spec.batch_norm = c.batch_norm;
  spec.dropout = c.dropout;
  spec.output_activation = act;
  return spec;
}

constexpr nn::Index ACCEL_INDEX = static_cast<nn::Index>(Action::kAccelerate);

// theta' <- tau theta + (1 - tau) theta' over the whole state (weights and batch-norm
// running statistics alike).
void softUpdate(nn::Network& target, const nn::Network& online, float tau) {
  nn::Vector t = target.getState();
  t += tau * (online.getState() - t);
  target.setState(t);
}

}  // namespace

void PdqnAgent::maskInvalidNextActions(const std::vector<ActionMask>& next_valid_actions,
                                       nn::Matrix& q) {
  constexpr float BLOCKED = -std::numeric_limits<float>::infinity();
  for (nn::Index j = 0; j < q.cols(); ++j) {
    const ActionMask valid = next_valid_actions[static_cast<size_t>(j)];
    for (nn::Index a = 0; a < ACTION_COUNT; ++a)
      if ((valid & actionBit(static_cast<Action>(a))) == 0) q(a, j) = BLOCKED;
  }
}

PdqnAgent::PdqnAgent(const PdqnConfig& config)
    : config_(validated(config)),
      rng_(std::make_unique<Rng>(config.seed)),
      mu_opt_(adamConfig(config)),
      q_opt_(adamConfig(config)),
      huber_(config.huber_delta),
      replay_(config.state_size, static_cast<size_t>(config.replay_capacity)),
      epsilon_(config.epsilon_start),
      accel_mid_(0.5f * (config.accel_max_mps2 + config.accel_min_mps2)),
      accel_half_(0.5f * (config.accel_max_mps2 - config.accel_min_mps2)) {
  // mu_theta: s -> tanh in [-1, 1]^1, scaled to [accel_min, accel_max] by accelFromNorm.
  mu_ = nn::makeMlp(mlpSpec(config_, config_.state_size, ACTION_PARAM_SIZE,
                            nn::OutputActivation::kTanh), *rng_);
  // Q_phi: concat(s, c_norm) -> one value per action. c enters normalised to [-1, 1] so
  // it has the scale of the (normalised) state features.
  q_ = nn::makeMlp(mlpSpec(config_, config_.state_size + ACTION_PARAM_SIZE, ACTION_COUNT,
                           nn::OutputActivation::kNone), *rng_);
  mu_.setRng(rng_.get());
  q_.setRng(rng_.get());
  mu_target_ = mu_;
  q_target_ = q_;
  mu_target_.eval();  // targets always use running statistics and no dropout
  q_target_.eval();
}

PdqnAgent::PdqnAgent(PdqnAgent&&) noexcept = default;
PdqnAgent& PdqnAgent::operator=(PdqnAgent&&) noexcept = default;
PdqnAgent::~PdqnAgent() = default;

void PdqnAgent::checkStates(const nn::Matrix& states, const char* who) const {
  if (states.rows() != config_.state_size || states.cols() < 1)
    throw std::invalid_argument(std::string(who) + ": states must be " +
                                std::to_string(config_.state_size) + " x n (n >= 1), got " +
                                std::to_string(states.rows()) + " x " +
                                std::to_string(states.cols()));
  if (!states.allFinite()) {
    for (nn::Index j = 0; j < states.cols(); ++j)
      for (nn::Index i = 0; i < states.rows(); ++i)
        if (!std::isfinite(states(i, j)))
          throw std::invalid_argument(std::string(who) + ": state feature " + std::to_string(i) +
                                      " of column " + std::to_string(j) + " is not finite");
  }
}

void PdqnAgent::buildQInput(const nn::Matrix& states, const nn::Matrix& c_norm,
                            nn::Matrix& out) const {
  const nn::Index n = states.cols(), s = config_.state_size;
  const nn::Index passes = config_.multi_pass ? ACTION_COUNT : 1;
  out.resize(s + ACTION_PARAM_SIZE, n * passes);
  for (nn::Index p = 0; p < passes; ++p) {
    out.block(0, p * n, s, n) = states;
    // MP-DQN: pass p carries only action p's own parameter; only a2 has one.
    if (!config_.multi_pass || p == ACCEL_INDEX)
      out.block(s, p * n, 1, n) = c_norm;
    else
      out.block(s, p * n, 1, n).setZero();
  }
}

void PdqnAgent::selectQ(const nn::Matrix& q_out, nn::Index n, nn::Matrix& out) const {
  if (!config_.multi_pass) {
    out = q_out;
    return;
  }
  // MP-DQN: Q_a(s) = the diagonal block, output a of pass a.
  out.resize(ACTION_COUNT, n);
  for (nn::Index a = 0; a < ACTION_COUNT; ++a) out.row(a) = q_out.block(a, a * n, 1, n);
}

void PdqnAgent::forwardGreedy(const nn::Matrix& states) {
  mu_.eval();
  q_.eval();
  // The folds equal the eval-mode networks within float rounding (folded_network_test).
  mu_fold_.refresh(mu_);
  q_fold_.refresh(q_);
  act_c_ = mu_fold_.forward(states);
  buildQInput(states, act_c_, act_q_in_);
  selectQ(q_fold_.forward(act_q_in_), states.cols(), act_q_);
}

void PdqnAgent::act(const nn::Matrix& states, bool explore, std::vector<Decision>& out) {
  checkStates(states, "PdqnAgent::act");
  decide(states, explore, nullptr, 0.0f, out);
}

void PdqnAgent::actOverDefaults(const nn::Matrix& states, bool explore, const std::vector<Decision>& defaults,
                                float margin, std::vector<Decision>& out) {
  checkStates(states, "PdqnAgent::actOverDefaults");
  if (defaults.size() != static_cast<size_t>(states.cols()))
    throw std::invalid_argument("PdqnAgent::actOverDefaults: " + std::to_string(defaults.size()) +
                                " defaults for " + std::to_string(states.cols()) + " states");
  if (!std::isfinite(margin) || margin < 0.0f)
    throw std::invalid_argument("PdqnAgent::actOverDefaults: margin " + std::to_string(margin) +
                                " must be finite and >= 0");
  decide(states, explore, &defaults, margin, out);
}

void PdqnAgent::decide(const nn::Matrix& states, bool explore, const std::vector<Decision>* defaults, float margin,
                       std::vector<Decision>& out) {
  forwardGreedy(states);
  out.resize(static_cast<size_t>(states.cols()));
  for (nn::Index j = 0; j < states.cols(); ++j) {
    nn::Index best = 0;
    act_q_.col(j).maxCoeff(&best);  // q* = argmax_q Q(s, c)_q (first on ties)
    float accel = accelFromNorm(act_c_(0, j));
    if (defaults) {
      const Decision& fallback = (*defaults)[static_cast<size_t>(j)];
      const auto d = static_cast<nn::Index>(fallback.action);
      if (act_q_(best, j) - act_q_(d, j) <= margin) {  // not worth departing from the default
        best = d;
        if (fallback.action == Action::kAccelerate) accel = fallback.accel_mps2;
      }
    }
    if (explore) {
      if (rng_->uniform01() < epsilon_) {
        best = static_cast<nn::Index>(rng_->uniformIndex(ACTION_COUNT));
        accel = rng_->uniform(config_.accel_min_mps2, config_.accel_max_mps2);
      } else if (config_.accel_noise_std_mps2 > 0) {
        accel += config_.accel_noise_std_mps2 * rng_->normal();
      }
    }
    accel = std::clamp(accel, config_.accel_min_mps2, config_.accel_max_mps2);
    out[static_cast<size_t>(j)] = Decision{static_cast<Action>(best), accel};
  }
  ++decision_rounds_;
  if (explore) {
    if (config_.epsilon_linear_rounds > 0.0) {
      // Linear over a stated share of the training budget (decision rounds).
      const double step = (config_.epsilon_start - config_.epsilon_final) / config_.epsilon_linear_rounds;
      epsilon_ = std::max(config_.epsilon_final, epsilon_ - step);
    } else {
      // eps <- max(eps_final, eps * decay), once per exploring decision round (paper).
      epsilon_ = std::max(config_.epsilon_final, epsilon_ * config_.epsilon_decay);
    }
  }
}

std::vector<Decision> PdqnAgent::act(const nn::Matrix& states, bool explore) {
  std::vector<Decision> out;
  act(states, explore, out);
  return out;
}

void PdqnAgent::evaluate(const nn::Matrix& states, nn::Matrix& q_values,
                         nn::Matrix& accel_mps2) {
  checkStates(states, "PdqnAgent::evaluate");
  forwardGreedy(states);
  q_values = act_q_;
  accel_mps2 = act_c_.unaryExpr([this](float c) { return accelFromNorm(c); });
}

void PdqnAgent::remember(const nn::Vector& state, const Decision& decision, float reward,
                         const nn::Vector& next_state, ActionMask next_valid_actions,
                         bool done) {
  const float accel =
      std::clamp(decision.accel_mps2, config_.accel_min_mps2, config_.accel_max_mps2);
  replay_.push(state, static_cast<int>(decision.action), accel, reward, next_state,
               next_valid_actions, done);
}

bool PdqnAgent::canUpdate() const {
  return replay_.size() >= static_cast<size_t>(config_.batch_size);
}

UpdateStats PdqnAgent::update() {
  if (!canUpdate())
    throw std::runtime_error("PdqnAgent::update: replay holds " +
                             std::to_string(replay_.size()) + " transitions, a batch needs " +
                             std::to_string(config_.batch_size));
  replay_.sample(static_cast<size_t>(config_.batch_size), *rng_, batch_);
  // bf16_products: the step's products in bfloat16, switched off again however it ends, so
  // act()'s decisions always run in float.
  struct Bf16Scope {
    PdqnAgent& agent;
    bool on;
    void set(bool value) const {
      for (nn::Network* net : {&agent.mu_, &agent.q_, &agent.mu_target_, &agent.q_target_})
        net->setBf16Products(value);
    }
    ~Bf16Scope() {
      if (on) set(false);
    }
  };
  const Bf16Scope bf16_scope{*this, config_.bf16_products};
  if (bf16_scope.on) bf16_scope.set(true);
  UpdateStats stats;
  stats.q_loss = updateQ();
  stats.param_loss = updateParam();
  ++gradient_steps_;
  if (config_.target_soft_tau > 0.0f) {
    softUpdate(mu_target_, mu_, config_.target_soft_tau);
    softUpdate(q_target_, q_, config_.target_soft_tau);
  } else if (gradient_steps_ % static_cast<uint64_t>(config_.target_update_steps) == 0) {
    // Hard target update every C gradient steps (DQN, Mnih et al. 2015).
    mu_target_.setState(mu_.getState());
    q_target_.setState(q_.getState());
  }
  stats.gradient_steps = gradient_steps_;
  return stats;
}

void PdqnAgent::nextStateValues(const nn::Matrix& next_states,
                                const std::vector<ActionMask>& next_valid_actions,
                                nn::Matrix& values) {
  if (next_valid_actions.size() != static_cast<size_t>(next_states.cols()))
    throw std::invalid_argument("PdqnAgent::nextStateValues: " +
                                std::to_string(next_valid_actions.size()) + " masks for " +
                                std::to_string(next_states.cols()) + " next states");
  // Targets are in eval mode and change every C steps only (hard copies): their folds are
  // reused between copies.
  mu_target_fold_.refresh(mu_target_);
  q_target_fold_.refresh(q_target_);
  c_norm_ = mu_target_fold_.forward(next_states);
  buildQInput(next_states, c_norm_, q_in_);
  selectQ(q_target_fold_.forward(q_in_), next_states.cols(), q_sel_);
  if (config_.td_target_valid_actions) maskInvalidNextActions(next_valid_actions, q_sel_);
  values = q_sel_.colwise().maxCoeff();
}

float PdqnAgent::updateQ() {
  const nn::Index n = config_.batch_size;
  const nn::Index passes = config_.multi_pass ? ACTION_COUNT : 1;
  // y = r + gamma (1 - done) max_a' Q_target(s', mu_target(s'))_a'   (P-DQN TD target)
  nextStateValues(batch_.next_states, batch_.next_valid_actions, next_values_);
  target_y_ = batch_.rewards.array() + config_.gamma * (1.0f - batch_.dones.array()) *
                                           next_values_.array();
  // Prediction Q_phi(s, c)_a with the stored (executed) parameter.
  c_norm_.resize(1, n);
  for (nn::Index j = 0; j < n; ++j) c_norm_(0, j) = normFromAccel(batch_.params(0, j));
  buildQInput(batch_.states, c_norm_, q_in_);
  q_.train();
  const nn::Matrix& out = q_.forward(q_in_);
  pred_.resize(1, n);
  for (nn::Index j = 0; j < n; ++j) {
    const nn::Index a = batch_.actions[static_cast<size_t>(j)];
    pred_(0, j) = out(a, passes > 1 ? a * n + j : j);
  }
  // L_Q = mean_n Huber(Q(s_n, c_n)_{a_n} - y_n); only the taken action gets a gradient.
  const float loss = huber_.compute(pred_, target_y_);
  grad_q_.setZero(out.rows(), out.cols());
  for (nn::Index j = 0; j < n; ++j) {
    const nn::Index a = batch_.actions[static_cast<size_t>(j)];
    grad_q_(a, passes > 1 ? a * n + j : j) = huber_.gradient()(0, j);
  }
  q_.backward(grad_q_, {true, q_.inputSize()});  // no input gradient needed
  q_opt_.step(q_);
  return loss;
}

float PdqnAgent::updateParam() {
  const nn::Index n = config_.batch_size;
  const nn::Index passes = config_.multi_pass ? ACTION_COUNT : 1;
  mu_.train();
  // Q is frozen for this loss: evaluated in eval mode, a fixed function of (s, c). In
  // training mode its batch norm would subtract the batch mean of W [s; c], so a shift of
  // c shared by the whole batch would get no gradient and mu could not learn the level of
  // the acceleration (measured: the learning test fails that way).
  q_.eval();
  c_norm_ = mu_.forward(batch_.states);
  buildQInput(batch_.states, c_norm_, q_in_);
  const nn::Matrix& out = q_.forward(q_in_);
  // L_theta = -(1/N) sum_n sum_a Q(s_n, mu(s_n))_a (P-DQN), so dL/dQ_a = -1/N.
  const float inv_n = 1.0f / static_cast<float>(n);
  double sum = 0.0;
  if (config_.param_loss_accelerate_only) {
    // Only Q_ACCELERATE(s, mu(s)): the head of the action the parameter belongs to.
    grad_q_.setZero(out.rows(), out.cols());
    const nn::Index col0 = passes > 1 ? ACCEL_INDEX * n : 0;
    sum = out.block(ACCEL_INDEX, col0, 1, n).cast<double>().sum();
    grad_q_.block(ACCEL_INDEX, col0, 1, n).setConstant(-inv_n);
  } else if (passes == 1) {
    sum = out.cast<double>().sum();
    grad_q_.setConstant(out.rows(), out.cols(), -inv_n);
  } else {
    grad_q_.setZero(out.rows(), out.cols());
    for (nn::Index a = 0; a < ACTION_COUNT; ++a) {
      sum += out.block(a, a * n, 1, n).cast<double>().sum();
      grad_q_.block(a, a * n, 1, n).setConstant(-inv_n);
    }
  }
  // Q is frozen here: propagate to its input row c only, no Q parameter gradients.
  const nn::Matrix& dq_in = q_.backward(grad_q_, {false, config_.state_size});
  grad_c_ = passes > 1 ? dq_in.middleCols(ACCEL_INDEX * n, n) : dq_in;
  mu_.backward(grad_c_, {true, mu_.inputSize()});
  mu_opt_.step(mu_);
  return static_cast<float>(-sum * inv_n);
}

}  // namespace palcas
