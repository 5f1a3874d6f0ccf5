// Map files: System::load_map (read, check, link, bags of words and the
// place database) and System::save_map (encode, atomic write) on a saved map
// (PVB_BENCH_MAP) with the settings of the run that made it
// (PVB_BENCH_SETTINGS, e.g. the run's camera.yaml).  Without them it skips.
// The file size per keyframe is reported as a counter, and so are the
// resident set after a load and before a save and its peak during each
// (the peak is reset through /proc/self/clear_refs).  Map.spillFeatures in
// the settings decides whether the keyframes' features lie in the spill
// file (loaded into it, and read back from it by the save).  Run pinned:
//   PVB_BENCH_MAP=DIR/maps/noon.pvbmap PVB_BENCH_SETTINGS=DIR/noon/camera.yaml
//   taskset -c 1 build/bin/bench_map_file --benchmark_repetitions=5
// (the two lines as one command).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "pvb/common/memory.hpp"

#include "pvb/slam/core/feature_spill.hpp"
#include "pvb/slam/core/loop_closing.hpp"
#include "pvb/slam/core/map_file.hpp"
#include "pvb/slam/core/place_recognition.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/core/system.hpp"

namespace {

const char* env(const char* name) {
  const char* v = std::getenv(name);
  return v && *v ? v : nullptr;
}

/// Sets the process's peak resident set back to its resident set now.
void reset_peak_resident() { std::ofstream("/proc/self/clear_refs") << "5"; }

/// VmHWM of /proc/self/status, MB (0 where it cannot be read).
double peak_resident_mb() {
  std::ifstream in("/proc/self/status");
  std::string key;
  double kb = 0;
  while (in >> key) {
    if (key == "VmHWM:") {
      in >> kb;
      break;
    }
    std::getline(in, key);
  }
  return kb / 1e3;
}

double resident_mb() { return static_cast<double>(pvb::resident_bytes()) / 1e6; }

/// False (the benchmark skipped) without a saved map and its settings.
bool inputs_set(benchmark::State& state) {
  if (env("PVB_BENCH_MAP") && env("PVB_BENCH_SETTINGS")) return true;
  state.SkipWithError("set PVB_BENCH_MAP and PVB_BENCH_SETTINGS");
  return false;
}

/// The saved map decoded into `map` (no System; the features in `spill`
/// when one is given); its keyframes in id order.
std::vector<std::shared_ptr<pvb::slam::KeyFrame>> decode_saved_map(
    pvb::slam::Map* map, const std::shared_ptr<pvb::slam::FeatureSpill>& spill = nullptr) {
  const pvb::slam::MapFileBytes bytes = pvb::slam::MapFileBytes::open(env("PVB_BENCH_MAP"));
  const pvb::slam::MapFileHeader head = pvb::slam::read_map_header(bytes);
  pvb::slam::decode_map(bytes, head, pvb::slam::camera_for(head.settings), map, spill);
  std::vector<std::shared_ptr<pvb::slam::KeyFrame>> kfs;
  for (const auto& [id, kf] : map->keyframes()) kfs.push_back(kf);
  return kfs;
}

std::unique_ptr<pvb::slam::System> make_system() {
  pvb::slam::SystemOptions o;
  o.synchronous = true;
  return std::make_unique<pvb::slam::System>(pvb::slam::read_settings(env("PVB_BENCH_SETTINGS")), o);
}

void BM_LoadMap(benchmark::State& state) {
  if (!inputs_set(state)) return;
  pvb::slam::MapLoadInfo info;
  for (auto _ : state) {
    state.PauseTiming();
    auto system = make_system();  // the vocabulary's load is not the map's
    const double before_mb = resident_mb();
    reset_peak_resident();
    state.ResumeTiming();
    info = system->load_map(env("PVB_BENCH_MAP"), pvb::slam::MapStart::kExtend);
    state.PauseTiming();
    if (!state.counters.count("rss_added_MB")) {  // later rounds reuse the heap the first one freed
      state.counters["rss_added_MB"] = resident_mb() - before_mb;
      state.counters["peak_added_MB"] = peak_resident_mb() - before_mb;
    }
    system.reset();
    state.ResumeTiming();
  }
  state.counters["keyframes"] = static_cast<double>(info.keyframes);
  state.counters["MB"] = static_cast<double>(info.bytes) / 1e6;
  state.counters["kB_per_keyframe"] = static_cast<double>(info.bytes) / 1e3 / static_cast<double>(info.keyframes);
}

void BM_SaveMap(benchmark::State& state) {
  if (!inputs_set(state)) return;
  auto system = make_system();
  system->load_map(env("PVB_BENCH_MAP"), pvb::slam::MapStart::kExtend);
  system->shutdown();
  const std::string out = std::string(env("PVB_BENCH_MAP")) + ".bench_copy";
  double before_mb = 0, peak_mb = 0;
  for (auto _ : state) {
    state.PauseTiming();
    before_mb = resident_mb();
    reset_peak_resident();
    state.ResumeTiming();
    benchmark::DoNotOptimize(system->save_map(out, "{}"));
    state.PauseTiming();
    peak_mb = std::max(peak_mb, peak_resident_mb());
    state.ResumeTiming();
  }
  state.counters["rss_before_MB"] = before_mb;
  state.counters["peak_MB"] = peak_mb;
  state.counters["peak_ratio"] = peak_mb / before_mb;
  std::remove(out.c_str());
}

/// Loop-candidate queries (PlaceRecognizer::loop_candidates, the bag-of-words
/// part of loop detection) against the saved map's first N keyframes, for
/// growing N: the 100 keyframes after the first N are asked, one each,
/// before they are added.  Counters: ms a query at each N.
void BM_LoopQuery(benchmark::State& state) {
  if (!inputs_set(state)) return;
  const pvb::slam::Settings settings = pvb::slam::read_settings(env("PVB_BENCH_SETTINGS"));
  pvb::slam::Map map;
  const auto kfs = decode_saved_map(&map);
  constexpr std::size_t kQueries = 100;
  for (auto _ : state) {
    pvb::slam::PlaceRecognizer place(pvb::slam::place::Vocabulary::load_shared(settings.vocabulary_path));
    std::size_t added = 0;
    for (std::size_t n : {std::size_t(1000), std::size_t(2500), std::size_t(5000), std::size_t(10000)}) {
      if (n + kQueries > kfs.size()) break;
      for (; added < n; ++added) place.add(*kfs[added]);
      std::size_t candidates = 0;
      const auto t0 = std::chrono::steady_clock::now();
      for (std::size_t q = n; q < n + kQueries; ++q) candidates += place.loop_candidates(map, *kfs[q], 30).size();
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      state.counters["ms_at_" + std::to_string(n)] = ms / kQueries;
      state.counters["cands_at_" + std::to_string(n)] = static_cast<double>(candidates) / kQueries;
    }
  }
}

/// A count from the environment variable `name`, else `fallback`.
std::size_t count_from_env(const char* name, std::size_t fallback) {
  const char* v = env(name);
  return v ? static_cast<std::size_t>(std::strtoull(v, nullptr, 10)) : fallback;
}

/// Loop detection replayed on the saved map (LoopClosing::process, then
/// the keyframe into the database, as the mapping thread does): the 200
/// keyframes after the first 5,000, with those 5,000 in the database
/// (PVB_BENCH_LOOP_FIRST and PVB_BENCH_LOOP_REPLAYED change the two, to
/// profile on a smaller map).  Counters: detection ms a keyframe (mean),
/// candidates and verifications a keyframe, those past the descriptor
/// matches (RANSAC and the guided search), and the verification's share
/// of the time.
void BM_LoopDetect(benchmark::State& state) {
  if (!inputs_set(state)) return;
  const pvb::slam::Settings settings = pvb::slam::read_settings(env("PVB_BENCH_SETTINGS"));
  const std::size_t kFirst = count_from_env("PVB_BENCH_LOOP_FIRST", 5000);
  const std::size_t kReplayed = count_from_env("PVB_BENCH_LOOP_REPLAYED", 200);
  for (auto _ : state) {
    state.PauseTiming();
    pvb::slam::Map map;
    const auto kfs = decode_saved_map(&map);
    if (kReplayed == 0 || kfs.size() < kFirst + kReplayed) {
      state.SkipWithError(
          "a map of PVB_BENCH_LOOP_FIRST + PVB_BENCH_LOOP_REPLAYED keyframes at least (5,200 by default)");
      return;
    }
    pvb::slam::PlaceRecognizer place(pvb::slam::place::Vocabulary::load_shared(settings.vocabulary_path));
    for (std::size_t i = 0; i < kFirst; ++i) place.add(*kfs[i]);
    pvb::slam::LoopClosing loop(map, settings.loop, &place);
    state.ResumeTiming();
    for (std::size_t i = kFirst; i < kFirst + kReplayed; ++i) {
      loop.process(kfs[i]);
      std::lock_guard<std::mutex> lock(map.mutex());
      if (!kfs[i]->bad()) place.add(*kfs[i]);
    }
    state.PauseTiming();
    const pvb::slam::LoopDetectTotals t = loop.detect_totals();
    const pvb::slam::LoopClosingStats st = loop.stats();
    state.counters["detect_ms"] = t.detect_ms / static_cast<double>(t.detections);
    state.counters["candidates"] = static_cast<double>(st.candidates) / kReplayed;
    state.counters["verified"] = static_cast<double>(st.verified) / kReplayed;
    state.counters["past_matches"] = static_cast<double>(st.verified - st.refused_matches) / kReplayed;
    state.counters["verify_share"] = st.verify_ms_total / t.detect_ms;
    state.counters["loops"] = static_cast<double>(st.loops.size());
    state.ResumeTiming();
  }
}

/// What a loop's correction does to every point of the map once the poses
/// are written back (MapPoint::update_normal_and_depth, under the map's
/// lock): here on the saved map with its features in a spill let go of
/// (written out, dropped from the process and the page cache), as a long
/// drive's far keyframes lie.  Counters: the resident set the pass adds
/// (feature pages read back), the map's points.
void BM_PointUpdate(benchmark::State& state) {
  if (!inputs_set(state)) return;
  auto spill = std::make_shared<pvb::slam::FeatureSpill>();
  pvb::slam::Map map;
  decode_saved_map(&map, spill);
  double added_mb = 0;
  for (auto _ : state) {
    state.PauseTiming();
    spill->release_resident();
    const double before_mb = resident_mb();
    state.ResumeTiming();
    {
      std::lock_guard<std::mutex> lock(map.mutex());
      for (const auto& [id, mp] : map.points())
        if (!mp->bad()) mp->update_normal_and_depth();
    }
    state.PauseTiming();
    added_mb = std::max(added_mb, resident_mb() - before_mb);
    state.ResumeTiming();
  }
  state.counters["rss_added_MB"] = added_mb;
  state.counters["points"] = static_cast<double>(map.num_points());
  spill->discard();
}

BENCHMARK(BM_LoadMap)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_SaveMap)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_LoopQuery)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_LoopDetect)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_PointUpdate)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
