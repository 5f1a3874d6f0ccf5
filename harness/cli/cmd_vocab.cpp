// pvbench vocab: trains a bag-of-words vocabulary (slam/place) from image
// folders, TUM sequences and scenarios rendered in memory, deterministically
// for a given seed, and writes it in our binary format (or DBoW2's text).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "command.hpp"
#include "count_option.hpp"
#include "io_plan.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/progress.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sensor/image_codec.hpp"
#include "pvb/sim/sim_frame_source.hpp"
#include "pvb/slam/features/orb_extractor.hpp"
#include "pvb/slam/place/vocabulary.hpp"
#include "pvb/suite/seeds.hpp"

namespace pvb::cli {
namespace {

namespace fs = std::filesystem;

struct VocabOptions {
  std::string out;
  std::vector<std::string> images, sequences, scenarios;
  std::string seeds;      ///< scenario seeds; empty: each scenario's own
  int every = 15;         ///< every n-th frame of a sequence or scenario
  int frames = 0;         ///< frames of each scenario run (0: its duration)
  int features = 1000;    ///< ORB features per image
  int k = 10, levels = 6;
  std::uint64_t seed = 1;
  std::string format = "binary";
  std::string gl = "auto";
};

/// Descriptors of the images, one matrix per image.
class Collector {
 public:
  explicit Collector(int features) : extractor_([&] {
    slam::OrbParams p;
    p.num_features = features;
    return p;
  }()) {}
  void add(const cv::Mat& image) {
    cv::Mat grey = image;
    if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
    descriptors.push_back(extractor_.extract(grey).descriptors.clone());
  }
  std::vector<cv::Mat> descriptors;

 private:
  slam::OrbExtractor extractor_;
};

bool is_image(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".ppm" || ext == ".pgm";
}

void add_image_folder(const std::string& dir, Collector* c) {
  if (!fs::is_directory(dir)) throw IoError(dir, "--images: expected a folder of images");
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && is_image(e.path())) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw IoError(dir, "--images: no .png, .jpg, .ppm or .pgm file in the folder");
  for (const auto& f : files) {
    const cv::Mat img = sensor::imread(f.string(), cv::IMREAD_GRAYSCALE);
    if (img.empty()) throw IoError(f.string(), "cannot read the image");
    c->add(img);
  }
}

/// Which of the source-specific options the command line gave.
struct VocabGiven {
  CLI::Option* seeds_opt = nullptr;
  CLI::Option* every_opt = nullptr;
  CLI::Option* frames_opt = nullptr;
  CLI::Option* gl_opt = nullptr;
  bool seeds = false, every = false, frames = false, gl = false;
};

void add_sequence(const std::string& dir, int every, Collector* c) {
  dataset::TumSequenceReader reader(dir, sensor::kTumDepthFactor, 0.02,
                                    dataset::MotionNeeds{});  // images only
  int i = 0;
  while (auto frame = reader.next())
    if (i++ % every == 0) c->add(frame->rgb);  // R,G,B: the grey conversion's channel order barely matters here
}

void add_scenario(const std::string& file, const std::vector<std::uint64_t>& seeds, const VocabOptions& o,
                  Collector* c) {
  const scenes::Scenario base = scenes::load_scenario(file);
  const std::vector<std::uint64_t> list = seeds.empty() ? std::vector<std::uint64_t>{base.seed} : seeds;
  for (std::uint64_t seed : list) {
    scenes::Scenario s = base;
    s.seed = seed;
    sim::SimFrameSource source(s, sim::parse_gl_backend(o.gl), o.frames);
    ProgressBar bar("vocab " + s.name + " seed " + std::to_string(seed), source.size_hint());
    // Only the frames used are rendered; the others advance the physics.
    for (int i = 0;; ++i) {
      if (i % o.every != 0) {
        if (!source.skip()) break;
      } else if (auto frame = source.next()) {
        c->add(frame->rgb);
      } else {
        break;
      }
      bar.update(static_cast<std::size_t>(i + 1));
    }
    bar.finish();
  }
}

/// Options that apply to some sources only are refused where none of those
/// is given, rather than ignored without a word.
void check_option_sources(const VocabOptions& o, const VocabGiven& given) {
  if (o.scenarios.empty()) {
    if (given.seeds) throw ConfigError("command line", "--seeds", "a --scenario to take the seeds of (images and sequences have none)");
    if (given.frames) throw ConfigError("command line", "--frames", "a --scenario whose run it limits");
    if (given.gl) throw ConfigError("command line", "--gl", "a --scenario to render");
  }
  if (given.every && o.scenarios.empty() && o.sequences.empty())
    throw ConfigError("command line", "--every", "a --sequence or --scenario (every image of --images is used)");
}

/// The vocabulary written never replaces an image, a sequence's file or a
/// scenario it is trained from.
void check_vocab_paths(const VocabOptions& o) {
  IoPlan plan;
  for (const std::string& dir : o.images) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec))
      if (e.is_regular_file(ec)) plan.input("an image of the --images folder", e.path().string());
  }
  for (const std::string& dir : o.sequences) add_sequence_inputs(&plan, "--sequence", dir);
  for (const std::string& file : o.scenarios)
    add_scenario_inputs(&plan, "--scenario", scenes::load_scenario(file));
  plan.output_file("--out", o.out).check();
}

int run_vocab(const VocabOptions& o, const VocabGiven& given) {
  if (o.images.empty() && o.sequences.empty() && o.scenarios.empty())
    throw ConfigError("command line", "--images/--sequence/--scenario", "at least one source of images");
  check_option_sources(o, given);
  check_vocab_paths(o);
  const auto t0 = std::chrono::steady_clock::now();
  Collector c(o.features);
  const std::vector<std::uint64_t> seeds = o.seeds.empty() ? std::vector<std::uint64_t>{}
                                                           : suite::parse_seed_list(o.seeds, "--seeds");
  for (const auto& d : o.images) add_image_folder(d, &c);
  for (const auto& d : o.sequences) add_sequence(d, o.every, &c);
  for (const auto& f : o.scenarios) add_scenario(f, seeds, o, &c);
  const double extract_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  slam::place::TrainParams p;
  p.k = o.k;
  p.levels = o.levels;
  p.seed = o.seed;
  slam::place::TrainReport report;
  const auto vocab = slam::place::Vocabulary::train(c.descriptors, p, &report);
  if (o.format == "text") vocab.save_text(o.out);
  else vocab.save_binary(o.out);
  std::error_code ec;  // a device or a FIFO (--out /dev/null) has no size
  const std::uintmax_t bytes = fs::is_regular_file(o.out, ec) ? fs::file_size(o.out, ec) : 0;
  std::printf("vocab: %zu images, %zu descriptors -> %zu words (%zu nodes, k %d, L %d, seed %llu); "
              "extraction %.1f s, training %.1f s; wrote %s%s\n",
              report.images, report.descriptors, report.words, report.nodes, o.k, o.levels,
              static_cast<unsigned long long>(o.seed), extract_s, report.seconds, o.out.c_str(),
              bytes > 0 ? format_number(" (%.1f MB)", static_cast<double>(bytes) / 1e6).c_str() : "");
  return 0;
}

}  // namespace

Command add_vocab_command(CLI::App& app) {
  auto opt = std::make_shared<VocabOptions>();
  CLI::App* sub = app.add_subcommand("vocab", "Train a bag-of-words vocabulary for place recognition");
  sub->add_option("--out", opt->out, "vocabulary file to write")
      ->required()
      ->check(path_check("vocab", "--out"));
  sub->add_option("--images", opt->images, "a folder of images (.png .jpg .ppm .pgm), every one used")
      ->check(path_check("vocab", "--images"));
  sub->add_option("--sequence", opt->sequences, "a TUM RGB-D folder (rgb.txt), every --every-th frame")
      ->check(path_check("vocab", "--sequence"));
  sub->add_option("--scenario", opt->scenarios, "a scenario rendered in memory, every --every-th frame")
      ->check(path_check("vocab", "--scenario"));
  auto given = std::make_shared<VocabGiven>();
  given->seeds_opt = sub->add_option("--seeds", opt->seeds, "scenario seeds, e.g. 101-103 or 101,105 (default: each scenario's own)");
  given->every_opt = sub->add_option("--every", opt->every, "use every n-th frame of sequences and scenarios")->check(CLI::Range(1, 100000));
  given->frames_opt = sub->add_option("--frames", opt->frames, "frames of each scenario run (0: its duration)")->check(CLI::Range(0, 10000000));
  sub->add_option("--features", opt->features, "ORB features per image")->check(CLI::Range(100, 20000));
  sub->add_option("--k", opt->k, "branching factor")->check(CLI::Range(2, 64));
  sub->add_option("--levels", opt->levels, "tree depth L")->check(CLI::Range(1, 8));
  sub->add_option("--seed", opt->seed, "k-means++ seed")
      ->check(seed_check("vocab", "--seed", std::numeric_limits<std::uint64_t>::max()));
  sub->add_option("--format", opt->format, "binary (ours, fast to load) or text (DBoW2, ORBvoc.txt)")
      ->check(CLI::IsMember({"binary", "text"}));
  given->gl_opt = sub->add_option("--gl", opt->gl, "rendering backend")->check(CLI::IsMember({"auto", "egl", "osmesa"}));
  return {sub, [opt, given] {
            given->seeds = given->seeds_opt->count() > 0;
            given->every = given->every_opt->count() > 0;
            given->frames = given->frames_opt->count() > 0;
            given->gl = given->gl_opt->count() > 0;
            return run_vocab(*opt, *given);
          }};
}

}  // namespace pvb::cli
