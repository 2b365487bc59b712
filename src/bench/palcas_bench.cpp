// palcas_bench: timings of the learning core (not a pass/fail test). Prints a table and
// writes JSON (--out FILE, default results/bench.json). Every figure is measured in BOTH
// thread CPU time (leaves out the time other processes hold the core: the machine is
// shared) and wall-clock time, over --reps repetitions (default 5), reporting the median of
// the per-repetition figures:
//   grad_step_ms_1thread: one full P-DQN update (both networks, batch 256, the paper
//     network, replay prefilled), mean over 20 updates per repetition;
//   grad_step_ms_2threads: the same with Eigen on 2 threads, wall-clock time;
//   infer_ms_p50 / infer_ms_p99 {"1","10","50","100","200"}: one batched greedy act() in
//     eval mode for that many CAVs, one thread, percentiles over the calls of a repetition;
//   act_after_update_ms {"100"}: act() for 100 CAVs right after an update (includes
//     re-folding both networks' batch norms, see FoldedNetwork);
//   fedavg_ms {"3","30","300"}: fedAverage of that many paper-size models;
//   load_average_start/end: /proc/loadavg 1-minute load when the run started / ended.
#include <Eigen/Core>

#include <algorithm>
#include <cstdlib>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "palcas_core/learning/fedavg.h"
#include "palcas_core/learning/pdqn_agent.h"

using namespace palcas;
using Clock = std::chrono::steady_clock;

#ifndef PALCAS_BENCH_FLAGS
#define PALCAS_BENCH_FLAGS "unknown"
#endif

namespace {

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// CPU time of the calling thread, ms.
double threadCpuMs() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const size_t i = std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())));
  return v[i];
}

nn::Matrix randomStates(nn::Index rows, nn::Index cols, Rng& rng) {
  nn::Matrix m(rows, cols);
  for (nn::Index i = 0; i < m.size(); ++i) m.data()[i] = rng.uniform(-1, 1);
  return m;
}

void prefill(PdqnAgent& agent, int count) {
  Rng rng(5);
  const nn::Index s = agent.config().state_size;
  for (int i = 0; i < count; ++i) {
    const Decision d{static_cast<Action>(rng.uniformIndex(4)), rng.uniform(-4.5f, 2.6f)};
    agent.remember(randomStates(s, 1, rng).col(0), d, rng.uniform(-1, 1),
                   randomStates(s, 1, rng).col(0), ALL_ACTIONS, i % 100 == 99);
  }
}

struct Timing {
  double cpu_ms = 0, wall_ms = 0;
};

// Runs `body` once and times it on both clocks.
template <typename Body>
Timing timed(Body&& body) {
  const double cpu_start = threadCpuMs();
  const auto start = Clock::now();
  body();
  return {threadCpuMs() - cpu_start, msSince(start)};
}

// Median over repetitions of per-repetition figures, each clock separately.
Timing median(const std::vector<Timing>& reps) {
  std::vector<double> cpu, wall;
  for (const Timing& t : reps) {
    cpu.push_back(t.cpu_ms);
    wall.push_back(t.wall_ms);
  }
  return {percentile(cpu, 0.5), percentile(wall, 0.5)};
}

// Percentile q of per-call timings, each clock separately.
Timing percentileOf(const std::vector<Timing>& calls, double q) {
  std::vector<double> cpu, wall;
  for (const Timing& t : calls) {
    cpu.push_back(t.cpu_ms);
    wall.push_back(t.wall_ms);
  }
  return {percentile(cpu, q), percentile(wall, q)};
}

Timing gradStepMs(PdqnAgent& agent, int threads, int reps) {
  Eigen::setNbThreads(threads);
  for (int i = 0; i < 3; ++i) agent.update();  // warm-up: sizes the scratch matrices
  constexpr int UPDATES = 20;
  std::vector<Timing> per_rep;
  for (int r = 0; r < reps; ++r) {
    Timing t = timed([&] {
      for (int i = 0; i < UPDATES; ++i) agent.update();
    });
    per_rep.push_back({t.cpu_ms / UPDATES, t.wall_ms / UPDATES});
  }
  return median(per_rep);
}

double loadAverage() {
  std::ifstream in("/proc/loadavg");
  double load = -1;
  in >> load;
  return load;
}

std::string jsonObject(const std::map<int, double>& values) {
  std::string text = "{";
  for (const auto& [key, value] : values) {
    char item[64];
    std::snprintf(item, sizeof item, "%s\"%d\": %.4f", text.size() > 1 ? ", " : "", key, value);
    text += item;
  }
  return text + "}";
}

const char* blasBackend() {
#ifdef EIGEN_USE_BLAS
  return "EIGEN_USE_BLAS (external BLAS)";
#else
  return "none: Eigen's own products; eval inference on FoldedNetwork's kernel";
#endif
}

struct InferResult {
  std::map<int, double> p50, p99, wall_p50, wall_p99;
};

// act() timings per batch size: per repetition the p50/p99 over its calls, then medians.
InferResult inferTimings(PdqnAgent& agent, int reps) {
  InferResult result;
  Rng rng(6);
  std::vector<Decision> decisions;
  for (int cavs : {1, 10, 50, 100, 200}) {
    const nn::Matrix states = randomStates(agent.config().state_size, cavs, rng);
    for (int i = 0; i < 20; ++i) agent.act(states, false, decisions);
    const int calls = cavs <= 50 ? 1000 : 400;
    std::vector<Timing> p50s, p99s;
    for (int r = 0; r < reps; ++r) {
      std::vector<Timing> samples;
      for (int i = 0; i < calls; ++i)
        samples.push_back(timed([&] { agent.act(states, false, decisions); }));
      p50s.push_back(percentileOf(samples, 0.50));
      p99s.push_back(percentileOf(samples, 0.99));
    }
    const Timing p50 = median(p50s), p99 = median(p99s);
    result.p50[cavs] = p50.cpu_ms;
    result.p99[cavs] = p99.cpu_ms;
    result.wall_p50[cavs] = p50.wall_ms;
    result.wall_p99[cavs] = p99.wall_ms;
  }
  return result;
}

// act() for 100 CAVs right after update(): the decision then re-folds both networks.
Timing actAfterUpdate(PdqnAgent& agent, int reps) {
  Rng rng(7);
  const nn::Matrix states = randomStates(agent.config().state_size, 100, rng);
  std::vector<Decision> decisions;
  std::vector<Timing> samples;
  for (int i = 0; i < 10 * reps; ++i) {
    agent.update();
    samples.push_back(timed([&] { agent.act(states, false, decisions); }));
  }
  return percentileOf(samples, 0.5);
}

std::map<int, Timing> fedAvgTimings(const ModelBlob& base, int reps) {
  std::map<int, Timing> result;
  std::vector<ModelBlob> all(300, base);
  for (size_t k = 0; k < all.size(); ++k) all[k].values[k] += 1e-3f;  // distinct models
  for (int count : {3, 30, 300}) {
    const std::vector<ModelBlob> models(all.begin(), all.begin() + count);
    const std::vector<uint64_t> n(static_cast<size_t>(count), 2500);
    std::vector<Timing> samples;
    for (int rep = 0; rep < reps; ++rep) {
      size_t size = 0;
      samples.push_back(timed([&] { size = fedAverage(models, n).values.size(); }));
      if (size != base.values.size()) std::abort();
    }
    result[count] = median(samples);
  }
  return result;
}

void printRow(const std::string& name, double cpu, double wall) {
  if (cpu < 0)
    std::printf("%-52s %10s %10.3f\n", name.c_str(), "-", wall);
  else
    std::printf("%-52s %10.3f %10.3f\n", name.c_str(), cpu, wall);
}

}  // namespace

int main(int argc, char** argv) {
  std::string out_path = "results/bench.json";
  int reps = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--out" && i + 1 < argc) {
      out_path = argv[++i];
    } else if (arg == "--reps" && i + 1 < argc && std::atoi(argv[i + 1]) > 0) {
      reps = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr,
                   "usage: palcas_bench [--out FILE] [--reps N]\n"
                   "  Times the learning core (paper network, float) and writes JSON to FILE\n"
                   "  (default results/bench.json). Figures are medians over N repetitions\n"
                   "  (default 5) in thread CPU time and wall-clock time. Run it when the\n"
                   "  machine is quiet: the JSON records the load average.\n");
      return arg == "--help" || arg == "-h" ? 0 : 2;
    }
  }
  const double load_start = loadAverage();
  PdqnConfig config;  // the paper's network and hyper-parameters
  PdqnAgent agent(config);
  prefill(agent, 10000);

  const Timing grad_1 = gradStepMs(agent, 1, reps);
  const Timing grad_2 = gradStepMs(agent, 2, reps);
  Eigen::setNbThreads(1);
  const InferResult infer = inferTimings(agent, reps);
  const Timing after_update = actAfterUpdate(agent, reps);
  const ModelBlob base = agent.exportModel();
  const std::map<int, Timing> fedavg = fedAvgTimings(base, reps);
  const double load_end = loadAverage();

  std::printf("PALCAS learning-core bench (flags: %s; Eigen SIMD: %s)\n", PALCAS_BENCH_FLAGS,
              Eigen::SimdInstructionSetsInUse());
  std::printf("BLAS backend: %s\n", blasBackend());
  std::printf("model: %zu floats (mu + Q, params + BN stats); %d repetitions, medians;"
              " load average %.2f -> %.2f\n",
              base.values.size(), reps, load_start, load_end);
  std::printf("%-52s %10s %10s\n", "measure", "cpu ms", "wall ms");
  printRow("P-DQN gradient step, batch 256, 1 thread", grad_1.cpu_ms, grad_1.wall_ms);
  printRow("P-DQN gradient step, batch 256, 2 threads", -1, grad_2.wall_ms);
  for (const auto& [cavs, p50] : infer.p50) {
    const std::string name = "act() " + std::to_string(cavs) + " CAVs, eval, 1 thread";
    printRow(name + ", p50", p50, infer.wall_p50.at(cavs));
    printRow(name + ", p99", infer.p99.at(cavs), infer.wall_p99.at(cavs));
  }
  printRow("act() 100 CAVs right after update(), p50", after_update.cpu_ms, after_update.wall_ms);
  for (const auto& [count, t] : fedavg)
    printRow("FedAvg of " + std::to_string(count) + " models", t.cpu_ms, t.wall_ms);

  std::map<int, double> fed_cpu, fed_wall;
  for (const auto& [count, t] : fedavg) {
    fed_cpu[count] = t.cpu_ms;
    fed_wall[count] = t.wall_ms;
  }
  const std::filesystem::path path(out_path);
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream out(out_path);
  out << "{\n"
      << "  \"compiler_flags\": \"" << PALCAS_BENCH_FLAGS << "\",\n"
      << "  \"eigen_simd\": \"" << Eigen::SimdInstructionSetsInUse() << "\",\n"
      << "  \"blas_backend\": \"" << blasBackend() << "\",\n"
      << "  \"repetitions\": " << reps << ",\n"
      << "  \"load_average_start\": " << load_start << ",\n"
      << "  \"load_average_end\": " << load_end << ",\n"
      << "  \"model_values\": " << base.values.size() << ",\n"
      << "  \"batch_size\": " << config.batch_size << ",\n"
      << "  \"timing\": \"medians over repetitions; plain names are thread CPU time, *_wall_* "
         "wall-clock\",\n"
      << "  \"grad_step_ms_1thread\": " << grad_1.cpu_ms << ",\n"
      << "  \"grad_step_wall_ms_1thread\": " << grad_1.wall_ms << ",\n"
      << "  \"grad_step_ms_2threads\": " << grad_2.wall_ms << ",\n"
      << "  \"infer_ms_p50\": " << jsonObject(infer.p50) << ",\n"
      << "  \"infer_ms_p99\": " << jsonObject(infer.p99) << ",\n"
      << "  \"infer_wall_ms_p50\": " << jsonObject(infer.wall_p50) << ",\n"
      << "  \"infer_wall_ms_p99\": " << jsonObject(infer.wall_p99) << ",\n"
      << "  \"act_after_update_ms\": {\"100\": " << after_update.cpu_ms << "},\n"
      << "  \"act_after_update_wall_ms\": {\"100\": " << after_update.wall_ms << "},\n"
      << "  \"fedavg_ms\": " << jsonObject(fed_cpu) << ",\n"
      << "  \"fedavg_wall_ms\": " << jsonObject(fed_wall) << "\n}\n";
  if (!out) {
    std::fprintf(stderr, "palcas_bench: cannot write %s\n", out_path.c_str());
    return 1;
  }
  std::printf("wrote %s\n", out_path.c_str());
  return 0;
}
