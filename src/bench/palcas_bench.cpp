// palcas_bench: timings of the learning core (not a pass/fail test) on Google Benchmark.
// Prints Google Benchmark's table and ours, and writes JSON (--out FILE, default
// results/bench.json). Every figure is measured in BOTH thread CPU time (leaves out the time
// other processes hold the core: the machine is shared) and wall-clock time, over --reps
// repetitions (default 5), reporting the median of the per-repetition figures:
//   grad_step_ms_1thread: one full P-DQN update (both networks, batch 256, the paper
//     network, replay prefilled), mean over 20 updates per repetition;
//   grad_step_ms_2threads: the same with Eigen on 2 threads, wall-clock time;
//   infer_ms_p50 / infer_ms_p99 {"1","10","50","100","200"}: one batched greedy act() in
//     eval mode for that many CAVs, one thread, percentiles over the calls of a repetition;
//   act_after_update_ms {"100"}: act() for 100 CAVs right after an update (includes
//     re-folding both networks' batch norms, see FoldedNetwork), p50 over 10 x reps calls;
//   fedavg_ms {"3","30","300"}: fedAverage of that many paper-size models;
//   grad_step_gflop: the multiply-adds of one update counted from the layer sizes (x 2 flops);
//   gemm_gflops_1thread: Eigen's rate on the network's largest product (512 x 256 times
//     256 x batch), one thread; grad_step_floor_ms = grad_step_gflop / that rate, the time the
//     update's own arithmetic needs on this core at best (what a faster kernel cannot beat
//     without doing less arithmetic or lower precision);
//   gemm_bf16_gflops_1thread: the same product in bfloat16 with float sums (AVX-512 BF16,
//     learning/nn/bf16_gemm.h; the input converted in each call, the weights packed once);
//     grad_step_bf16_bound_ms = the step with its arithmetic at that rate and the rest of it
//     (the step minus grad_step_floor_ms) unchanged: what a bfloat16 step could reach at best
//     (null where the build has no AVX-512 BF16);
//   grad_step_bf16_ms_1thread: the gradient step with learning/bf16_products on (its products
//     in bfloat16 where the layer shapes fit), same network, batch and prefill, one thread
//     (null without AVX-512 BF16); grad_step_bf16_ratio = that / grad_step_ms_1thread;
//   load_average_start/end: /proc/loadavg 1-minute load when the run started / ended.
// Google Benchmark runs the repetitions, times the fixed iteration counts and takes the
// medians; percentiles over single calls are no figure of its own, so those benchmarks time
// each call on both clocks and hand the percentiles to it as counters.
#include <benchmark/benchmark.h>

#include <Eigen/Core>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

#include "palcas_core/learning/fedavg.h"
#include "palcas_core/learning/nn/bf16_gemm.h"
#include "palcas_core/learning/nn/linear.h"
#include "palcas_core/learning/pdqn_agent.h"

using namespace palcas;
using Clock = std::chrono::steady_clock;

#ifndef PALCAS_BENCH_FLAGS
#define PALCAS_BENCH_FLAGS "unknown"
#endif

namespace {

constexpr int CAV_COUNTS[] = {1, 10, 50, 100, 200};
constexpr int MODEL_COUNTS[] = {3, 30, 300};

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

// Per-call timings on both clocks, for the percentile figures.
class CallTimes {
 public:
  template <typename Body>
  void time(Body&& body) {
    const double cpu_start = threadCpuMs();
    const auto start = Clock::now();
    body();
    cpu_.push_back(threadCpuMs() - cpu_start);
    wall_.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
  }
  /// Percentile q of the calls as counters <prefix>_cpu_ms / <prefix>_wall_ms of `state`;
  /// Google Benchmark's median aggregate then takes their median over repetitions.
  void report(benchmark::State& state, const std::string& prefix, double q) const {
    state.counters[prefix + "_cpu_ms"] = percentile(cpu_, q);
    state.counters[prefix + "_wall_ms"] = percentile(wall_, q);
  }

 private:
  std::vector<double> cpu_, wall_;
};

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

// Multiply-adds per sample of a dense network's forward pass: sum of in x out over its layers.
double denseMacs(int in, const std::vector<int>& hidden, int out) {
  double macs = 0;
  for (int width : hidden) {
    macs += static_cast<double>(in) * width;
    in = width;
  }
  return macs + static_cast<double>(in) * out;
}

// Flops of one PdqnAgent::update() without multi-pass, counted as its products run (see
// updateQ / updateParam): the targets' forward passes (mu', Q'); Q's forward, weight and
// input gradients (no gradient into the state rows of its first layer); mu's forward, Q's
// forward and its input gradient back to c (Q frozen), mu's weight gradients and its input
// gradients below the first layer. Element-wise work (batch norm, dropout, Adam) is left out.
double gradStepGflop(const PdqnConfig& c) {
  const int s = c.state_size;
  const double mu = denseMacs(s, c.hidden_sizes, ACTION_PARAM_SIZE);
  const double q = denseMacs(s + ACTION_PARAM_SIZE, c.hidden_sizes, ACTION_COUNT);
  const double first = static_cast<double>(c.hidden_sizes.front());
  const double q_first = (s + ACTION_PARAM_SIZE) * first, mu_first = s * first;
  const double targets = mu + q;
  const double update_q = q + q + (q - q_first);
  const double update_param = mu + q + (q - q_first + ACTION_PARAM_SIZE * first) + mu + (mu - mu_first);
  return 2.0 * c.batch_size * (targets + update_q + update_param) * 1e-9;
}

// The benchmarks, in the order they run (registration order); all share one agent, as the
// figures always did (the decision timings run on an agent that has been updated).
void registerBenchmarks(PdqnAgent& agent, PdqnAgent* agent_bf16, ModelBlob& base, int reps) {
  if (agent_bf16 != nullptr) {
    benchmark::RegisterBenchmark("grad_step_bf16/threads:1", [agent_bf16](benchmark::State& state) {
      Eigen::setNbThreads(1);
      for (int i = 0; i < 3; ++i) agent_bf16->update();
      for (auto _ : state) agent_bf16->update();
    })->Iterations(20);
  }
  for (int threads : {1, 2}) {
    benchmark::RegisterBenchmark(
        ("grad_step/threads:" + std::to_string(threads)).c_str(),
        [&agent, threads](benchmark::State& state) {
          Eigen::setNbThreads(threads);
          for (int i = 0; i < 3; ++i) agent.update();  // warm-up: sizes the scratch matrices
          for (auto _ : state) agent.update();
          Eigen::setNbThreads(1);
        })
        ->Iterations(20);  // a repetition's figure: the mean over 20 updates
  }
  // Eigen's float product at the network's largest layer (512 x 256) times a batch, one thread.
  const int widest = *std::max_element(agent.config().hidden_sizes.begin(), agent.config().hidden_sizes.end());
  const double largest_layer_gflop = 2.0 * widest * 256.0 * agent.config().batch_size * 1e-9;
  benchmark::RegisterBenchmark("gemm_largest_layer", [&agent, widest, largest_layer_gflop](benchmark::State& state) {
    Rng rng(8);
    // Through the library's own Linear layer (its product is Eigen's GEMM; the bias add is
    // 1/256 of the work), which also keeps Eigen's products out of this file.
    nn::Linear layer(256, widest, rng);
    const nn::Matrix batch = randomStates(256, agent.config().batch_size, rng);
    Eigen::setNbThreads(1);
    for (auto _ : state) benchmark::DoNotOptimize(layer.forward(batch, false).data());
    state.counters["gflop"] = largest_layer_gflop;
  })->Iterations(200);
  if (nn::bf16GemmAvailable()) {
    benchmark::RegisterBenchmark("gemm_largest_layer_bf16", [&agent, widest, largest_layer_gflop](benchmark::State& state) {
      Rng rng(8);
      const nn::Bf16Weights weights = nn::packBf16(randomStates(widest, 256, rng));
      const nn::Matrix batch = randomStates(256, agent.config().batch_size, rng);
      nn::Matrix out;
      std::vector<uint16_t> scratch;
      for (auto _ : state) {
        nn::bf16Gemm(weights, batch, out, scratch);
        benchmark::DoNotOptimize(out.data());
      }
      state.counters["gflop"] = largest_layer_gflop;
    })->Iterations(200);
  }
  for (int cavs : CAV_COUNTS) {
    benchmark::RegisterBenchmark(
        ("act/cavs:" + std::to_string(cavs)).c_str(),
        [&agent, cavs](benchmark::State& state) {
          Rng rng(static_cast<uint64_t>(6 + cavs));
          const nn::Matrix states = randomStates(agent.config().state_size, cavs, rng);
          std::vector<Decision> decisions;
          for (int i = 0; i < 20; ++i) agent.act(states, false, decisions);  // warm-up
          CallTimes calls;
          for (auto _ : state) calls.time([&] { agent.act(states, false, decisions); });
          calls.report(state, "p50", 0.50);
          calls.report(state, "p99", 0.99);
        })
        ->Iterations(cavs <= 50 ? 1000 : 400);
  }
  // act() for 100 CAVs right after update(): the decision then re-folds both networks. One
  // repetition of 10 x reps calls: its p50 is the figure.
  benchmark::RegisterBenchmark("act_after_update/cavs:100", [&agent](benchmark::State& state) {
    Rng rng(7);
    const nn::Matrix states = randomStates(agent.config().state_size, 100, rng);
    std::vector<Decision> decisions;
    CallTimes calls;
    for (auto _ : state) {
      state.PauseTiming();
      agent.update();
      state.ResumeTiming();
      calls.time([&] { agent.act(states, false, decisions); });
    }
    calls.report(state, "p50", 0.50);
  })->Iterations(10 * reps)->Repetitions(1);
  for (int count : MODEL_COUNTS) {
    benchmark::RegisterBenchmark(
        ("fedavg/models:" + std::to_string(count)).c_str(),
        [&agent, &base, count](benchmark::State& state) {
          // The agent's model after every update above (not timed: before the loop).
          if (base.values.empty()) base = agent.exportModel();
          std::vector<ModelBlob> models(static_cast<size_t>(count), base);
          for (size_t k = 0; k < models.size(); ++k) models[k].values[k] += 1e-3f;  // distinct
          const std::vector<uint64_t> n(models.size(), 2500);
          size_t size = 0;
          for (auto _ : state) size = fedAverage(models, n).values.size();
          if (size != base.values.size()) state.SkipWithError("fedAverage changed the size");
        })
        ->Iterations(1);
  }
}

// Keeps each benchmark's median over repetitions (or its single run) by name, and shows
// Google Benchmark's own table as it goes.
class Collector : public benchmark::ConsoleReporter {
 public:
  explicit Collector(OutputOptions options) : ConsoleReporter(options) {}
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      if (run.error_occurred) failed_ = true;
      const bool single = run.repetitions <= 1 && run.run_type == Run::RT_Iteration;
      if (single || (run.run_type == Run::RT_Aggregate && run.aggregate_name == "median"))
        medians_[run.run_name.function_name] = run;
    }
    ConsoleReporter::ReportRuns(runs);
  }
  bool failed() const { return failed_; }
  Timing time(const std::string& name) const {
    const Run& run = medians_.at(name);
    return {run.GetAdjustedCPUTime(), run.GetAdjustedRealTime()};
  }
  double value(const std::string& name, const std::string& counter) const {
    return medians_.at(name).counters.at(counter);
  }
  Timing counters(const std::string& name, const std::string& prefix) const {
    const Run& run = medians_.at(name);
    return {run.counters.at(prefix + "_cpu_ms"), run.counters.at(prefix + "_wall_ms")};
  }

 private:
  std::map<std::string, Run> medians_;
  bool failed_ = false;
};

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
                   "  Times the learning core (paper network, float) on Google Benchmark and\n"
                   "  writes JSON to FILE (default results/bench.json). Figures are medians over\n"
                   "  N repetitions (default 5) in thread CPU time and wall-clock time. Run it\n"
                   "  when the machine is quiet: the JSON records the load average.\n");
      return arg == "--help" || arg == "-h" ? 0 : 2;
    }
  }
  // Every benchmark runs --reps times and reports only its aggregates (the median is ours);
  // milliseconds as the figures are.
  const std::string repetitions = "--benchmark_repetitions=" + std::to_string(reps);
  char* gb_argv[] = {argv[0], const_cast<char*>(repetitions.c_str()),
                     const_cast<char*>("--benchmark_report_aggregates_only=true"),
                     const_cast<char*>("--benchmark_time_unit=ms"), nullptr};
  int gb_argc = 4;
  benchmark::Initialize(&gb_argc, gb_argv);

  const double load_start = loadAverage();
  PdqnConfig config;  // the paper's network and hyper-parameters
  PdqnAgent agent(config);
  prefill(agent, 10000);
  std::unique_ptr<PdqnAgent> agent_bf16;
  if (nn::bf16GemmAvailable()) {
    PdqnConfig low = config;
    low.bf16_products = true;
    agent_bf16 = std::make_unique<PdqnAgent>(low);
    prefill(*agent_bf16, 10000);
  }
  Eigen::setNbThreads(1);
  ModelBlob base_model;  // exported by the first FedAvg benchmark
  registerBenchmarks(agent, agent_bf16.get(), base_model, reps);
  // Colours only on a terminal: a log of ./palcas bench gets no escape codes.
  Collector collector(isatty(fileno(stdout)) ? benchmark::ConsoleReporter::OO_ColorTabular
                                             : benchmark::ConsoleReporter::OO_Tabular);
  benchmark::RunSpecifiedBenchmarks(&collector);
  benchmark::Shutdown();
  const double load_end = loadAverage();
  if (collector.failed()) {
    std::fprintf(stderr, "palcas_bench: a benchmark failed (above)\n");
    return 1;
  }

  const Timing grad_1 = collector.time("grad_step/threads:1");
  const Timing grad_2 = collector.time("grad_step/threads:2");
  std::map<int, double> p50, p99, wall_p50, wall_p99, fed_cpu, fed_wall;
  for (int cavs : CAV_COUNTS) {
    const std::string name = "act/cavs:" + std::to_string(cavs);
    const Timing median_p50 = collector.counters(name, "p50");
    const Timing median_p99 = collector.counters(name, "p99");
    p50[cavs] = median_p50.cpu_ms;
    wall_p50[cavs] = median_p50.wall_ms;
    p99[cavs] = median_p99.cpu_ms;
    wall_p99[cavs] = median_p99.wall_ms;
  }
  const Timing after_update = collector.counters("act_after_update/cavs:100", "p50");
  const double step_gflop = gradStepGflop(config);
  const double gemm_gflops = collector.value("gemm_largest_layer", "gflop") / (collector.time("gemm_largest_layer").cpu_ms * 1e-3);
  const double step_gflops = step_gflop / (grad_1.cpu_ms * 1e-3);
  const double floor_ms = step_gflop / gemm_gflops * 1e3;
  const bool bf16 = nn::bf16GemmAvailable();
  const double bf16_gflops =
      bf16 ? collector.value("gemm_largest_layer_bf16", "gflop") / (collector.time("gemm_largest_layer_bf16").cpu_ms * 1e-3)
           : 0.0;
  const double bf16_bound_ms = bf16 ? grad_1.cpu_ms - floor_ms + step_gflop / bf16_gflops * 1e3 : 0.0;
  const Timing grad_bf16 = bf16 ? collector.time("grad_step_bf16/threads:1") : Timing{};
  for (int count : MODEL_COUNTS) {
    const Timing t = collector.time("fedavg/models:" + std::to_string(count));
    fed_cpu[count] = t.cpu_ms;
    fed_wall[count] = t.wall_ms;
  }

  std::printf("PALCAS learning-core bench (flags: %s; Eigen SIMD: %s)\n", PALCAS_BENCH_FLAGS,
              Eigen::SimdInstructionSetsInUse());
  std::printf("BLAS backend: %s\n", blasBackend());
  std::printf("model: %zu floats (mu + Q, params + BN stats); %d repetitions, medians;"
              " load average %.2f -> %.2f\n",
              base_model.values.size(), reps, load_start, load_end);
  std::printf("%-52s %10s %10s\n", "measure", "cpu ms", "wall ms");
  printRow("P-DQN gradient step, batch 256, 1 thread", grad_1.cpu_ms, grad_1.wall_ms);
  printRow("P-DQN gradient step, batch 256, 2 threads", -1, grad_2.wall_ms);
  if (bf16) printRow("P-DQN gradient step, bf16 products, 1 thread", grad_bf16.cpu_ms, grad_bf16.wall_ms);
  for (int cavs : CAV_COUNTS) {
    const std::string name = "act() " + std::to_string(cavs) + " CAVs, eval, 1 thread";
    printRow(name + ", p50", p50[cavs], wall_p50[cavs]);
    printRow(name + ", p99", p99[cavs], wall_p99[cavs]);
  }
  printRow("act() 100 CAVs right after update(), p50", after_update.cpu_ms, after_update.wall_ms);
  for (int count : MODEL_COUNTS)
    printRow("FedAvg of " + std::to_string(count) + " models", fed_cpu[count], fed_wall[count]);
  std::printf("gradient step arithmetic: %.3f GFLOP at %.1f GFLOP/s; Eigen's product of the widest layer"
              " runs %.1f GFLOP/s, so the same arithmetic needs >= %.2f ms here (%.0f %% of the step)\n",
              step_gflop, step_gflops, gemm_gflops, floor_ms, 100.0 * floor_ms / grad_1.cpu_ms);
  if (bf16) {
    std::printf("bfloat16 (AVX-512 BF16): the widest layer's product runs %.1f GFLOP/s (%.2f x Eigen's float);"
                " a step with its arithmetic at that rate and the rest unchanged: >= %.2f ms (%.2f x today's)\n",
                bf16_gflops, bf16_gflops / gemm_gflops, bf16_bound_ms, bf16_bound_ms / grad_1.cpu_ms);
    std::printf("the step with learning/bf16_products: %.2f ms, %.2f x the float step\n", grad_bf16.cpu_ms,
                grad_bf16.cpu_ms / grad_1.cpu_ms);
  } else {
    std::printf("bfloat16: not measured (this build has no AVX-512 BF16)\n");
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
      << "  \"model_values\": " << base_model.values.size() << ",\n"
      << "  \"batch_size\": " << config.batch_size << ",\n"
      << "  \"timing\": \"medians over repetitions; plain names are thread CPU time, *_wall_* "
         "wall-clock\",\n"
      << "  \"grad_step_ms_1thread\": " << grad_1.cpu_ms << ",\n"
      << "  \"grad_step_wall_ms_1thread\": " << grad_1.wall_ms << ",\n"
      << "  \"grad_step_ms_2threads\": " << grad_2.wall_ms << ",\n"
      << "  \"infer_ms_p50\": " << jsonObject(p50) << ",\n"
      << "  \"infer_ms_p99\": " << jsonObject(p99) << ",\n"
      << "  \"infer_wall_ms_p50\": " << jsonObject(wall_p50) << ",\n"
      << "  \"infer_wall_ms_p99\": " << jsonObject(wall_p99) << ",\n"
      << "  \"act_after_update_ms\": {\"100\": " << after_update.cpu_ms << "},\n"
      << "  \"act_after_update_wall_ms\": {\"100\": " << after_update.wall_ms << "},\n"
      << "  \"fedavg_ms\": " << jsonObject(fed_cpu) << ",\n"
      << "  \"fedavg_wall_ms\": " << jsonObject(fed_wall) << ",\n"
      << "  \"grad_step_gflop\": " << step_gflop << ",\n"
      << "  \"grad_step_gflops_1thread\": " << step_gflops << ",\n"
      << "  \"gemm_gflops_1thread\": " << gemm_gflops << ",\n"
      << "  \"grad_step_floor_ms\": " << floor_ms << ",\n"
      << "  \"gemm_bf16_gflops_1thread\": " << (bf16 ? std::to_string(bf16_gflops) : "null") << ",\n"
      << "  \"grad_step_bf16_bound_ms\": " << (bf16 ? std::to_string(bf16_bound_ms) : "null") << ",\n"
      << "  \"grad_step_bf16_ms_1thread\": " << (bf16 ? std::to_string(grad_bf16.cpu_ms) : "null") << ",\n"
      << "  \"grad_step_bf16_ratio\": " << (bf16 ? std::to_string(grad_bf16.cpu_ms / grad_1.cpu_ms) : "null")
      << "\n}\n";
  if (!out) {
    std::fprintf(stderr, "palcas_bench: cannot write %s\n", out_path.c_str());
    return 1;
  }
  std::printf("wrote %s\n", out_path.c_str());
  return 0;
}
