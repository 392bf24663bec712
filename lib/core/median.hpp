// The median of a list of values, found by partial sorting (the list is reordered).
#pragma once

#include <algorithm>
#include <vector>

namespace gmpu {

// The middle value (of an even count, the upper of the two middle ones); the list must not
// be empty.
template <class T>
T median_in_place(std::vector<T> &values) {
    const auto middle = values.begin() + long(values.size() / 2);
    std::nth_element(values.begin(), middle, values.end());
    return *middle;
}

}  // namespace gmpu
