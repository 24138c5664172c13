// A running mean and its standard error, for the Monte Carlo tests that compare two estimators
// of one expectation (tests/lights, tests/render/test_photon_guide.cpp).
#pragma once

#include <algorithm>
#include <cmath>

namespace pb::test {

struct Mean {
  double sum = 0, sum2 = 0;
  int n = 0;
  void add(double x) {
    sum += x;
    sum2 += x * x;
    ++n;
  }
  double mean() const { return sum / n; }
  double se() const { return std::sqrt(std::max(0.0, sum2 / n - mean() * mean()) / n); }
};

}  // namespace pb::test
