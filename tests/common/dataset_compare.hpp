#pragma once
// Two datasets equal bit for bit: every array and every attribute of core/dataset.hpp (what the
// producer's resume and MPI tests promise; NaN attributes compare by their bits too).
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "core/dataset.hpp"

namespace yarnhom::test {

inline bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}
inline bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

inline void expect_identical(const Dataset& a, const Dataset& b, const std::string& where) {
  EXPECT_EQ(a.pattern, b.pattern) << where;
  EXPECT_EQ(a.source, b.source) << where;
  EXPECT_EQ(a.note, b.note) << where;
  EXPECT_TRUE(same_bits(a.psi0, b.psi0)) << where;
  EXPECT_TRUE(same_bits(a.areal_density, b.areal_density)) << where;
  EXPECT_TRUE(same_bits(a.rest_q, b.rest_q)) << where;
  EXPECT_TRUE(same_bits(a.grad0, b.grad0)) << where;
  EXPECT_TRUE(same_bits(a.lattice_original, b.lattice_original)) << where;
  EXPECT_TRUE(same_bits(a.lattice_relaxed, b.lattice_relaxed)) << where;
  EXPECT_TRUE(same_bits(a.rest_hessian, b.rest_hessian)) << where;
  EXPECT_TRUE(same_bits(a.rve_tiles, b.rve_tiles)) << where;
  ASSERT_EQ(a.terms.size(), b.terms.size()) << where;
  for (size_t t = 0; t < a.terms.size(); ++t) {
    const TermData &x = a.terms[t], &y = b.terms[t];
    EXPECT_EQ(x.term.name, y.term.name) << where;
    ASSERT_EQ(x.n, y.n) << where << " term " << x.term.name;
    EXPECT_TRUE(same_bits(x.strain, y.strain)) << where << " term " << x.term.name;
    EXPECT_TRUE(same_bits(x.raw, y.raw)) << where << " term " << x.term.name;
    EXPECT_TRUE(same_bits(x.energy, y.energy)) << where << " term " << x.term.name;
    EXPECT_TRUE(same_bits(x.gradient, y.gradient)) << where << " term " << x.term.name;
    EXPECT_TRUE(same_bits(x.lower, y.lower)) << where << " term " << x.term.name;
    EXPECT_TRUE(same_bits(x.upper, y.upper)) << where << " term " << x.term.name;
  }
}

}  // namespace yarnhom::test
