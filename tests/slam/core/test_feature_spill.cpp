// FeatureSpill (slam/core/feature_spill): blocks that keep their bytes when
// their pages leave memory, and frames whose features move into it.
#include "pvb/slam/core/feature_spill.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <random>
#include <vector>

#include "file_size_limit.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/memory.hpp"
#include "pvb/slam/core/frame.hpp"

namespace pvb::slam {
namespace {

constexpr std::size_t kChunk = std::size_t(1) << 20;

TEST(FeatureSpill, BlocksKeepTheirBytesWhenTheirPagesLeaveMemory) {
  FeatureSpill spill({}, kChunk);
  std::mt19937 rng(7);
  std::vector<std::vector<unsigned char>> want;
  std::vector<unsigned char*> blocks;
  for (int b = 0; b < 40; ++b) {  // 40 blocks of 1-60 KB: more than one chunk
    std::vector<unsigned char> bytes(1024 + rng() % (60 * 1024));
    for (auto& c : bytes) c = static_cast<unsigned char>(rng());
    auto* p = static_cast<unsigned char*>(spill.allocate(bytes.size()));
    ASSERT_EQ(reinterpret_cast<std::uintptr_t>(p) % 64, 0u);
    std::memcpy(p, bytes.data(), bytes.size());
    want.push_back(std::move(bytes));
    blocks.push_back(p);
  }
  EXPECT_GT(spill.stats().file_bytes, kChunk);
  EXPECT_GT(spill.resident_bytes(), 0u);

  spill.release_resident();
  EXPECT_EQ(spill.resident_bytes(), 0u);  // neither in the process nor in the page cache
  EXPECT_EQ(spill.stats().releases, 1u);
  for (std::size_t b = 0; b < blocks.size(); ++b)
    ASSERT_EQ(std::memcmp(blocks[b], want[b].data(), want[b].size()), 0) << "block " << b;
  EXPECT_GT(spill.resident_bytes(), 0u);  // read back
}

// A map's load and save: pages dropped from the process without being
// written out first keep their bytes (the page cache holds them), and a
// read-ahead pass reads them all back.
TEST(FeatureSpill, PagesDroppedFromTheProcessOnlyKeepTheirBytesAndReadAheadReadsThemBack) {
  constexpr std::size_t kBlock = std::size_t(2) << 20;
  FeatureSpill spill({}, 4 * kBlock);
  std::vector<unsigned char*> blocks;
  const std::size_t rss_before = resident_bytes();
  for (int b = 0; b < 4; ++b) {  // 8 MB, written, not synced
    auto* p = static_cast<unsigned char*>(spill.allocate(kBlock));
    for (std::size_t i = 0; i < kBlock; ++i) p[i] = static_cast<unsigned char>(i * 31 + b);
    blocks.push_back(p);
  }
  const std::size_t rss_written = resident_bytes();
  EXPECT_GT(rss_written, rss_before + 6 * (kBlock / 2));
  spill.drop_from_process();
  EXPECT_LT(resident_bytes(), rss_written - 6 * (kBlock / 2));
  const auto same = [&] {
    for (int b = 0; b < 4; ++b)
      for (std::size_t i = 0; i < kBlock; i += 4093)
        if (blocks[b][i] != static_cast<unsigned char>(i * 31 + b)) return false;
    return true;
  };
  EXPECT_TRUE(same());
  spill.release_resident();  // now on disk only
  spill.read_ahead();
  EXPECT_EQ(spill.resident_bytes(), spill.stats().file_bytes);  // all in the page cache
  EXPECT_TRUE(same());
  spill.end_read_ahead();
  EXPECT_TRUE(same());
}

// A folder it cannot write, and a file that cannot grow (a full disk, here
// the process's file size limit), are one IoError each, never a fault.
TEST(FeatureSpill, AFileThatCannotBeMadeOrGrownIsAnIoError) {
  EXPECT_THROW(FeatureSpill("/nonexistent-folder-for-features"), IoError);
  FeatureSpill spill({}, kChunk);
  std::string message;
  {
    const test::FileSizeLimit limit(kChunk + kChunk / 2);
    EXPECT_NE(spill.allocate(kChunk / 2), nullptr);  // the first chunk fits
    try {
      spill.allocate(kChunk);  // a second chunk does not
    } catch (const IoError& e) {
      message = e.what();
    }
  }
  EXPECT_NE(message.find("cannot grow the keyframe feature file"), std::string::npos) << message;
  EXPECT_EQ(spill.stats().file_bytes, kChunk);
}

TEST(FeatureSpill, AFreedBlockLeavesTheNeighboursIntact) {
  FeatureSpill spill({}, kChunk);
  auto* a = static_cast<unsigned char*>(spill.allocate(10000));
  auto* b = static_cast<unsigned char*>(spill.allocate(50000));
  auto* c = static_cast<unsigned char*>(spill.allocate(10000));
  std::memset(a, 0xa1, 10000);
  std::memset(b, 0xb2, 50000);
  std::memset(c, 0xc3, 10000);
  spill.deallocate(b, 50000);  // its whole pages are punched out of the file
  spill.release_resident();
  for (int i = 0; i < 10000; ++i) {
    ASSERT_EQ(a[i], 0xa1) << i;
    ASSERT_EQ(c[i], 0xc3) << i;
  }
  const FeatureSpillStats s = spill.stats();
  EXPECT_EQ(s.allocated_bytes - s.freed_bytes, 10048u + 10048u);  // 64-byte granules
}

// A freed block's whole pages are punched out (they read as zeros), but
// not once the spill is discarded: tearing a map down costs no syscalls.
TEST(FeatureSpill, FreedPagesArePunchedOutUntilTheSpillIsDiscarded) {
  FeatureSpill spill({}, kChunk);
  const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  const auto freed_then_read = [&] {
    auto* p = static_cast<unsigned char*>(spill.allocate(4 * page));
    std::memset(p, 0xab, 4 * page);
    spill.deallocate(p, 4 * page);
    return p[2 * page];  // a whole page inside the block, still mapped
  };
  EXPECT_EQ(freed_then_read(), 0);
  spill.discard();
  EXPECT_EQ(freed_then_read(), 0xab);
  EXPECT_EQ(spill.stats().live_bytes(), 0u);  // counted either way
}

TEST(FeatureSpill, ContainersMoveIntoItAndCopiesGoBackToTheHeap) {
  FeatureSpill spill({}, kChunk);
  FeatureArray<float> heap = {1.5f, -2.0f, 3.25f};
  FeatureArray<float> spilled = spilled_copy(heap, &spill);
  EXPECT_EQ(spilled, heap);
  EXPECT_EQ(feature_heap_bytes(spilled), 0u);
  EXPECT_EQ(feature_spilled_bytes(spilled), 3 * sizeof(float));
  FeatureArray<float> copy = spilled;
  EXPECT_EQ(copy.get_allocator().spill(), nullptr);
  EXPECT_EQ(copy, heap);
  FeatureArray<float> moved;
  moved = std::move(spilled);  // the spill travels with the buffer
  EXPECT_EQ(moved.get_allocator().spill(), &spill);
  EXPECT_EQ(moved, heap);
}

// A copy into the spill is written through the file: the process maps
// none of its pages until it reads them, and then reads the same values.
// On the heap, resize() still value-initialises.
TEST(FeatureSpill, ACopyGoesThroughTheFileWithoutFaultingItsPagesIn) {
  FeatureSpill spill({}, std::size_t(16) << 20);
  FeatureArray<cv::Point2f> heap(std::size_t(1) << 20);  // 8 MB
  for (std::size_t i = 0; i < heap.size(); ++i) heap[i] = {static_cast<float>(i), -static_cast<float>(i) / 2};
  const std::size_t rss_before = resident_bytes();
  const FeatureArray<cv::Point2f> spilled = spilled_copy(heap, &spill);
  EXPECT_LT(resident_bytes(), rss_before + (std::size_t(2) << 20));  // not 8 MB more
  spill.release_resident();
  EXPECT_EQ(spilled, heap);
  FeatureArray<float> zeros;
  zeros.resize(1000);
  for (float z : zeros) ASSERT_EQ(z, 0.0f);
}

std::shared_ptr<const CameraModel> plain_camera() {
  StereoIntrinsics K;
  K.fx = K.fy = 520.0;
  K.cx = 320.0;
  K.cy = 240.0;
  K.bf = 40.0;
  return std::make_shared<const CameraModel>(CameraModel::make(K, 640, 480, {}, 3.0, 1.2, 8));
}

Frame random_frame(const std::shared_ptr<const CameraModel>& cam, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 639.0f), v(0.0f, 479.0f);
  OrbFeatures f;
  for (int i = 0; i < n; ++i)
    f.keypoints.emplace_back(cv::Point2f(u(rng), v(rng)), 31.0f, float(rng() % 360), 50.0f, int(rng() % 8));
  f.descriptors = cv::Mat(n, 32, CV_8U);
  cv::randu(f.descriptors, 0, 256);
  cv::Mat depth(480, 640, CV_32F);
  cv::randu(depth, -1.0, 6.0);  // about a seventh without depth
  return Frame(3, 42, std::move(f), depth, cam);
}

TEST(FeatureSpill, ASpilledFrameReadsTheSameAndHoldsItsFeaturesOffTheHeap) {
  const auto cam = plain_camera();
  const Frame original = random_frame(cam, 900, 11);
  Frame f = original;
  auto spill = std::make_shared<FeatureSpill>(std::string(), kChunk);
  f.spill_features(spill);
  ASSERT_TRUE(f.features_spilled());
  spill->release_resident();

  ASSERT_EQ(f.size(), original.size());
  for (std::size_t i = 0; i < f.size(); ++i) {
    ASSERT_EQ(f.keys[i], original.keys[i]);
    ASSERT_EQ(f.keys_un[i].pt, original.keys_un[i].pt);
    ASSERT_EQ(f.keys_un[i].octave, original.keys_un[i].octave);
    ASSERT_EQ(f.depth_m[i], original.depth_m[i]);
    ASSERT_EQ(f.u_right[i], original.u_right[i]);
    ASSERT_EQ(descriptor_distance(f.descriptors.ptr<unsigned char>(int(i)),
                                  original.descriptors.ptr<unsigned char>(int(i))), 0);
  }
  for (double u = 5; u < 640; u += 97)
    for (double v = 5; v < 480; v += 61)
      ASSERT_EQ(f.features_in_area(u, v, 40.0, 1, 5), original.features_in_area(u, v, 40.0, 1, 5));

  const FrameMemory m = f.memory(), m0 = original.memory();
  EXPECT_EQ(m.keypoints, 0u);
  EXPECT_EQ(m.descriptors, 0u);
  EXPECT_EQ(m.grid, 0u);
  EXPECT_LT(m.per_keypoint, m0.per_keypoint);  // the map-point links and flags stay
  EXPECT_GE(m.spilled, 900u * (8 + 16 + 32 + 4 + 4));
  EXPECT_EQ(m0.spilled, 0u);

  Frame copy = f;  // on the heap again, but for the descriptors' shared block
  EXPECT_EQ(copy.memory().keypoints, m0.keypoints);
  EXPECT_EQ(copy.keys_un.size(), original.keys_un.size());

  f.release_features();  // a culled keyframe gives its blocks back; the copy's descriptors stay
  EXPECT_EQ(descriptor_distance(copy.descriptors.ptr<unsigned char>(0), original.descriptors.ptr<unsigned char>(0)), 0);
}

}  // namespace
}  // namespace pvb::slam
