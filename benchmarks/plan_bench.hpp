// kdl_space_bench --plan SCENARIO (issue 38): planCapture on a scenario as the tool runs it: the
// instant objective (base_rate, the default box and scan) and the operation objective (the peak
// base rate over 10 s after each capture); the counter `evaluations` gives the time per
// configuration. The same source is built against the library before a change to time both
// side by side (docs/benchmarks.md).
#pragma once

#include <benchmark/benchmark.h>

#include <string>

#include "kdl_space/planning/capture_plan.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"

namespace kdl_space::bench {

inline void registerPlan(const std::string& path) {
  static const Scenario scenario = loadScenario(path);
  benchmark::RegisterBenchmark("plan/instant", [](benchmark::State& st) {
    for (auto _ : st) {
      const CapturePlan p = planCapture(scenario, PlanOptions{});
      benchmark::DoNotOptimize(p.optimum.objective);
      st.counters["evaluations"] = p.evaluations;
    }
  })->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("plan/operation_10s", [](benchmark::State& st) {
    PlanOptions o;
    o.weights = {{"peak_base_rate", 1.0}};
    o.horizon = 10.0;
    for (auto _ : st) {
      const CapturePlan p = planCapture(scenario, o);
      benchmark::DoNotOptimize(p.optimum.objective);
      st.counters["evaluations"] = p.evaluations;
    }
  })->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3);
}

}  // namespace kdl_space::bench
