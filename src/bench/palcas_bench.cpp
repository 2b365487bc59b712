// palcas_bench: timings of the learning core (not a pass/fail test). Prints a table and
// writes JSON (--out FILE, default results/bench.json):
//   grad_step_ms_1thread: one full P-DQN update (both networks, batch 256, the paper
//     network, replay prefilled), mean over repetitions, THREAD CPU TIME (the machine is
//     shared; CPU time leaves out the time other processes hold the core);
//   grad_step_ms_2threads: the same with Eigen on 2 threads, wall-clock time;
//   infer_ms_p50 / infer_ms_p99 {"1","10","50","100","200"}: one batched greedy act() in
//     eval mode for that many CAVs, one thread, thread CPU time per call;
//   *_wall_* : the same measures in wall-clock time;
//   fedavg_ms {"3","30","300"}: fedAverage of that many paper-size models, median wall.
#include <Eigen/Core>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "palcas_core/fedavg.h"
#include "palcas_core/pdqn_agent.h"

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
                   randomStates(s, 1, rng).col(0), i % 100 == 99);
  }
}

struct Timing {
  double cpu_ms, wall_ms;
};

Timing gradStepMs(PdqnAgent& agent, int threads, int reps) {
  Eigen::setNbThreads(threads);
  for (int i = 0; i < 3; ++i) agent.update();  // warm-up: sizes the scratch matrices
  const double cpu_start = threadCpuMs();
  const auto start = Clock::now();
  for (int i = 0; i < reps; ++i) agent.update();
  return {(threadCpuMs() - cpu_start) / reps, msSince(start) / reps};
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

}  // namespace

int main(int argc, char** argv) {
  std::string out_path = "results/bench.json";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--out" && i + 1 < argc) {
      out_path = argv[++i];
    } else {
      std::fprintf(stderr, "usage: palcas_bench [--out FILE]\n");
      return 2;
    }
  }
  PdqnConfig config;  // the paper's network and hyper-parameters
  PdqnAgent agent(config);
  prefill(agent, 10000);

  const Timing grad_1 = gradStepMs(agent, 1, 40);
  const Timing grad_2 = gradStepMs(agent, 2, 40);
  Eigen::setNbThreads(1);

  std::map<int, double> infer_p50, infer_p99, wall_p50, wall_p99;
  Rng rng(6);
  std::vector<Decision> decisions;
  for (int cavs : {1, 10, 50, 100, 200}) {
    const nn::Matrix states = randomStates(config.state_size, cavs, rng);
    for (int i = 0; i < 20; ++i) agent.act(states, false, decisions);
    std::vector<double> cpu, wall;
    const int reps = cavs <= 50 ? 2000 : 1000;
    for (int i = 0; i < reps; ++i) {
      const double cpu_start = threadCpuMs();
      const auto start = Clock::now();
      agent.act(states, false, decisions);
      cpu.push_back(threadCpuMs() - cpu_start);
      wall.push_back(msSince(start));
    }
    infer_p50[cavs] = percentile(cpu, 0.50);
    infer_p99[cavs] = percentile(cpu, 0.99);
    wall_p50[cavs] = percentile(wall, 0.50);
    wall_p99[cavs] = percentile(wall, 0.99);
  }

  std::map<int, double> fedavg_ms;
  const ModelBlob base = agent.exportModel();
  std::vector<ModelBlob> all(300, base);
  for (size_t k = 0; k < all.size(); ++k) all[k].values[k] += 1e-3f;  // distinct models
  for (int count : {3, 30, 300}) {
    const std::vector<ModelBlob> models(all.begin(), all.begin() + count);
    const std::vector<uint64_t> n(static_cast<size_t>(count), 2500);
    std::vector<double> samples;
    for (int rep = 0; rep < (count < 300 ? 10 : 3); ++rep) {
      const auto start = Clock::now();
      const ModelBlob avg = fedAverage(models, n);
      samples.push_back(msSince(start));
      if (avg.values.size() != base.values.size()) return 1;
    }
    fedavg_ms[count] = percentile(samples, 0.5);
  }

  std::printf("PALCAS learning-core bench (flags: %s; Eigen SIMD: %s)\n", PALCAS_BENCH_FLAGS,
              Eigen::SimdInstructionSetsInUse());
  std::printf("model: %zu floats (mu + Q, params + BN stats)\n", base.values.size());
  std::printf("%-52s %10s %10s\n", "measure", "cpu ms", "wall ms");
  std::printf("%-52s %10.3f %10.3f\n", "P-DQN gradient step, batch 256, 1 thread", grad_1.cpu_ms,
              grad_1.wall_ms);
  std::printf("%-52s %10s %10.3f\n", "P-DQN gradient step, batch 256, 2 threads", "-",
              grad_2.wall_ms);
  for (const auto& [cavs, p50] : infer_p50) {
    const std::string name = "act() " + std::to_string(cavs) + " CAVs, eval, 1 thread";
    std::printf("%-52s %10.3f %10.3f\n", (name + ", p50").c_str(), p50, wall_p50[cavs]);
    std::printf("%-52s %10.3f %10.3f\n", (name + ", p99").c_str(), infer_p99[cavs],
                wall_p99[cavs]);
  }
  for (const auto& [count, ms] : fedavg_ms)
    std::printf("%-52s %10s %10.3f\n", ("FedAvg of " + std::to_string(count) + " models").c_str(),
                "-", ms);

  const std::filesystem::path path(out_path);
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream out(out_path);
  out << "{\n"
      << "  \"compiler_flags\": \"" << PALCAS_BENCH_FLAGS << "\",\n"
      << "  \"eigen_simd\": \"" << Eigen::SimdInstructionSetsInUse() << "\",\n"
      << "  \"model_values\": " << base.values.size() << ",\n"
      << "  \"batch_size\": " << config.batch_size << ",\n"
      << "  \"timing\": \"1-thread figures are thread CPU time; *_wall_* are wall-clock\",\n"
      << "  \"grad_step_ms_1thread\": " << grad_1.cpu_ms << ",\n"
      << "  \"grad_step_wall_ms_1thread\": " << grad_1.wall_ms << ",\n"
      << "  \"grad_step_ms_2threads\": " << grad_2.wall_ms << ",\n"
      << "  \"infer_ms_p50\": " << jsonObject(infer_p50) << ",\n"
      << "  \"infer_ms_p99\": " << jsonObject(infer_p99) << ",\n"
      << "  \"infer_wall_ms_p50\": " << jsonObject(wall_p50) << ",\n"
      << "  \"infer_wall_ms_p99\": " << jsonObject(wall_p99) << ",\n"
      << "  \"fedavg_ms\": " << jsonObject(fedavg_ms) << "\n}\n";
  if (!out) {
    std::fprintf(stderr, "palcas_bench: cannot write %s\n", out_path.c_str());
    return 1;
  }
  std::printf("wrote %s\n", out_path.c_str());
  return 0;
}
