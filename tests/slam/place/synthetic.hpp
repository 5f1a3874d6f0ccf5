#pragma once
// Synthetic 256-bit descriptors with known clusters, temporary files and a
// toy vocabulary written by hand in DBoW2's text format.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace pvb::slam::place::test {

using Desc = std::array<unsigned char, 32>;

inline Desc random_desc(std::mt19937_64& rng) {
  Desc d;
  for (auto& b : d) b = static_cast<unsigned char>(rng() & 0xFFU);
  return d;
}

/// `d` with exactly `flips` distinct bits flipped, chosen at random.
inline Desc flip_bits(Desc d, int flips, std::mt19937_64& rng) {
  std::set<unsigned> bits;
  while (static_cast<int>(bits.size()) < flips) bits.insert(static_cast<unsigned>(rng() % 256));
  for (const unsigned b : bits) d[b / 8] ^= static_cast<unsigned char>(1U << (b % 8));
  return d;
}

inline int distance(const Desc& a, const Desc& b) {
  int n = 0;
  for (std::size_t i = 0; i < a.size(); ++i) n += __builtin_popcount(static_cast<unsigned>(a[i] ^ b[i]));
  return n;
}

inline Desc from_ptr(const unsigned char* p) {
  Desc d;
  std::copy(p, p + 32, d.begin());
  return d;
}

/// Rows of a CV_8U N x 32 matrix.
inline cv::Mat to_mat(const std::vector<Desc>& rows) {
  cv::Mat m(static_cast<int>(rows.size()), 32, CV_8U);
  for (std::size_t r = 0; r < rows.size(); ++r)
    std::copy(rows[r].begin(), rows[r].end(), m.ptr(static_cast<int>(r)));
  return m;
}

/// `n` random centres, each at least `min_distance` bits from the others.
inline std::vector<Desc> far_centres(int n, int min_distance, std::mt19937_64& rng) {
  std::vector<Desc> c;
  while (static_cast<int>(c.size()) < n) {
    const Desc d = random_desc(rng);
    bool far = true;
    for (const Desc& e : c) far = far && distance(d, e) >= min_distance;
    if (far) c.push_back(d);
  }
  return c;
}

inline std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "pvb_place_" + name + "_" + std::to_string(::getpid());
}

inline std::string desc_text(const Desc& d) {
  std::string s;
  for (const unsigned char b : d) s += std::to_string(b) + " ";
  return s;
}

/// The toy vocabulary (k = 2, L = 2, DBoW2's text layout):
///
///   node 1  parent 0, inner, A  = 32 zero bytes
///   node 2  parent 0, inner, B  = 32 bytes 255
///   node 3  parent 1, word 0, A1 = A,                         IDF 0.5
///   node 4  parent 1, word 1, A2 = bytes 0-3 255, others 0,   IDF 1
///   node 5  parent 2, word 2, B1 = B,                         IDF 2
///   node 6  parent 2, word 3, B2 = bytes 0-3 0, others 255,   IDF 0 (a stop word)
inline Desc toy_a() { return Desc{}; }
inline Desc toy_b() {
  Desc d;
  d.fill(255);
  return d;
}
inline Desc toy_a2() {
  Desc d{};
  for (int i = 0; i < 4; ++i) d[i] = 255;
  return d;
}
inline Desc toy_b2() {
  Desc d = toy_b();
  for (int i = 0; i < 4; ++i) d[i] = 0;
  return d;
}
inline std::string toy_text() {
  return "2 2  0 0\n"
         "0 0 " +
         desc_text(toy_a()) +
         " 0\n"
         "0 0 " +
         desc_text(toy_b()) +
         " 0\n"
         "1 1 " +
         desc_text(toy_a()) +
         " 0.5\n"
         "1 1 " +
         desc_text(toy_a2()) +
         " 1\n"
         "2 1 " +
         desc_text(toy_b()) +
         " 2\n"
         "2 1 " +
         desc_text(toy_b2()) + " 0\n";
}

}  // namespace pvb::slam::place::test
