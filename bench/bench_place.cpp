// Place recognition: bag-of-words transform, L1 score, keyframe-database
// query and binary vocabulary load, on a vocabulary (k = 10, L = 6) trained
// on real ORB descriptors: the 18 images of the shared data (Oxford wall
// and trees, the TUM pairs), each also mirrored (rBRIEF is not mirror
// invariant, so a mirrored image gives new descriptors), 5000 features
// each.  BM_Train adds the images scaled by 1.5 (about twice the
// descriptors); BM_LoadBinary/1 loads a vocabulary of about a million
// nodes trained on random descriptors.  Run pinned:
//   taskset -c 1 build/bin/bench_place --benchmark_repetitions=5
//     --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "pvb/slam/features/orb_extractor.hpp"
#include "pvb/slam/place/database.hpp"
#include "pvb/slam/place/vocabulary.hpp"

namespace {

namespace pl = pvb::slam::place;

const std::string kData = std::string(PVB_SHARED_DIR) + "/data/";

std::vector<std::string> image_paths() {
  std::vector<std::string> out;
  for (const char* scene : {"oxford/wall/", "oxford/trees/"}) {
    for (int i = 1; i <= 6; ++i) out.push_back(kData + scene + "img" + std::to_string(i) + ".ppm");
  }
  for (const char* pair : {"tum/fr1_xyz_pair/rgb/", "tum/fr3_long_office_household_pair/rgb/"}) {
    for (const cv::String& p : [&] {
           std::vector<cv::String> found;
           cv::glob(kData + pair + "*.png", found);
           return found;
         }()) {
      out.push_back(p);
    }
  }
  out.push_back(kData + "tum/fr2_desk_pair/1.png");
  out.push_back(kData + "tum/fr2_desk_pair/2.png");
  return out;
}

/// Descriptors per image variant: each image as it is and mirrored, and
/// with `scaled` also both at 1.5 times the size.
std::vector<cv::Mat> extract(bool scaled) {
  pvb::slam::OrbParams params;
  params.num_features = 5000;
  pvb::slam::OrbExtractor orb(params);
  std::vector<cv::Mat> out;
  for (const std::string& path : image_paths()) {
    const cv::Mat img = cv::imread(path, cv::IMREAD_GRAYSCALE);
    if (img.empty()) {
      std::fprintf(stderr, "bench_place: cannot read %s\n", path.c_str());
      std::exit(1);
    }
    std::vector<cv::Mat> variants{img, cv::Mat()};
    cv::flip(img, variants[1], 1);
    if (scaled) {
      for (int v = 0; v < 2; ++v) {
        cv::Mat big;
        cv::resize(variants[static_cast<std::size_t>(v)], big, cv::Size(), 1.5, 1.5, cv::INTER_LINEAR);
        variants.push_back(big);
      }
    }
    for (const cv::Mat& v : variants) out.push_back(orb.extract(v).descriptors.clone());
  }
  return out;
}

std::size_t rows(const std::vector<cv::Mat>& m) {
  std::size_t n = 0;
  for (const cv::Mat& x : m) n += static_cast<std::size_t>(x.rows);
  return n;
}

const std::vector<cv::Mat>& corpus() {
  static const std::vector<cv::Mat> c = extract(false);
  return c;
}

pl::Vocabulary train(const std::vector<cv::Mat>& images) {
  pl::TrainParams p;  // k = 10, L = 6
  pl::TrainReport r;
  pl::Vocabulary voc = pl::Vocabulary::train(images, p, &r);
  std::fprintf(stderr, "bench_place: trained on %zu images, %zu descriptors: %zu nodes, %zu words, %.2f s\n",
               r.images, r.descriptors, r.nodes, r.words, r.seconds);
  return voc;
}

const pl::Vocabulary& vocabulary() {
  static const pl::Vocabulary v = train(corpus());
  return v;
}

/// `n` descriptors drawn (with a fixed seed) from image `image` of the corpus.
cv::Mat sample(std::size_t image, int n, std::uint64_t seed) {
  const cv::Mat& all = corpus().at(image % corpus().size());
  std::mt19937_64 rng(seed);
  cv::Mat out(n, 32, CV_8U);
  for (int i = 0; i < n; ++i)
    all.row(static_cast<int>(rng() % static_cast<std::uint64_t>(all.rows))).copyTo(out.row(i));
  return out;
}

void BM_Transform(benchmark::State& state) {
  const pl::Vocabulary& voc = vocabulary();
  const cv::Mat d = sample(0, static_cast<int>(state.range(0)), 1);
  pl::BowVector bow;
  pl::FeatureVector fv;
  for (auto _ : state) {
    voc.transform(d, &bow, &fv, 4);
    benchmark::DoNotOptimize(bow.size());
  }
  state.counters["words"] = static_cast<double>(bow.size());
}
BENCHMARK(BM_Transform)->Arg(1000)->Arg(2000)->Unit(benchmark::kMillisecond);

void BM_Score(benchmark::State& state) {
  const pl::Vocabulary& voc = vocabulary();
  pl::BowVector a, b;
  voc.transform(sample(0, 1000, 1), &a);
  voc.transform(sample(2, 1000, 2), &b);  // the wall from another viewpoint (1 is image 0 mirrored)
  double s = 0;
  for (auto _ : state) {
    s = pl::Vocabulary::score(a, b);
    benchmark::DoNotOptimize(s);
  }
  state.counters["score"] = s;
}
BENCHMARK(BM_Score)->Unit(benchmark::kMicrosecond);

/// A database of `range(0)` keyframes, each 1000 descriptors drawn from one
/// corpus image; the query is drawn from image 0 with another seed.
void BM_DatabaseQuery(benchmark::State& state) {
  const pl::Vocabulary& voc = vocabulary();
  pl::Database db;
  const auto n = static_cast<std::size_t>(state.range(0));
  for (std::size_t i = 0; i < n; ++i) {
    pl::BowVector bow;
    voc.transform(sample(i, 1000, 100 + i), &bow);
    db.add(i, bow);
  }
  pl::BowVector query;
  voc.transform(sample(0, 1000, 7), &query);
  std::size_t found = 0;
  for (auto _ : state) {
    const std::vector<pl::Candidate> c = db.query(query, 0.0);
    found = c.size();
    benchmark::DoNotOptimize(c.data());
  }
  state.counters["candidates"] = static_cast<double>(found);
}
BENCHMARK(BM_DatabaseQuery)->Arg(1000)->Arg(5000)->Unit(benchmark::kMillisecond);

/// A vocabulary file, written once and removed at exit: 0 the real one,
/// 1 one trained (k = 10, L = 6) on 1.2 million random descriptors, which
/// fill the tree to about a million nodes.
struct SavedFile {
  std::string path;
  explicit SavedFile(int which)
      : path("/tmp/bench_place_" + std::to_string(::getpid()) + "_" + std::to_string(which) + ".bin") {
    if (which == 0) {
      vocabulary().save_binary(path);
      return;
    }
    std::mt19937_64 rng(3);
    std::vector<cv::Mat> images;
    for (int i = 0; i < 1200; ++i) {
      cv::Mat m(1000, 32, CV_8U);
      for (int r = 0; r < m.rows; ++r) {
        for (int c = 0; c < 32; ++c) m.at<unsigned char>(r, c) = static_cast<unsigned char>(rng() & 0xFFU);
      }
      images.push_back(m);
    }
    train(images).save_binary(path);
  }
  ~SavedFile() { std::remove(path.c_str()); }
};

const std::string& saved(int which) {
  static const SavedFile real(0);
  if (which == 0) return real.path;
  static const SavedFile big(1);
  return big.path;
}

/// Loads `path` once per iteration; the node count as a counter.
void load_repeatedly(benchmark::State& state, const std::string& path) {
  std::size_t nodes = 0;
  for (auto _ : state) {
    const pl::Vocabulary v = pl::Vocabulary::load(path);
    nodes = v.node_count();
    benchmark::DoNotOptimize(nodes);
  }
  state.counters["nodes"] = static_cast<double>(nodes);
}

void BM_LoadBinary(benchmark::State& state) { load_repeatedly(state, saved(static_cast<int>(state.range(0)))); }
BENCHMARK(BM_LoadBinary)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

/// The default vocabulary (trained at build time), as every run loads it.
void BM_LoadDefault(benchmark::State& state) { load_repeatedly(state, PVB_DEFAULT_VOCABULARY_FILE); }
BENCHMARK(BM_LoadDefault)->Unit(benchmark::kMillisecond);

/// Training from scratch: range(0) = 0 on the corpus, 1 on the corpus with
/// the scaled images too.
void BM_Train(benchmark::State& state) {
  const std::vector<cv::Mat> images = state.range(0) == 0 ? corpus() : extract(true);
  for (auto _ : state) {
    const pl::Vocabulary v = train(images);
    benchmark::DoNotOptimize(v.size());
  }
  state.counters["descriptors"] = static_cast<double>(rows(images));
}
BENCHMARK(BM_Train)->Arg(0)->Arg(1)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
