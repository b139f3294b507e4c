// Small robust statistics shared by the report, the intrinsics and guidance.
#pragma once

#include <algorithm>
#include <vector>

namespace calibench {

// The median (the upper one of an even count); 0 for no values.
inline double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

}  // namespace calibench
