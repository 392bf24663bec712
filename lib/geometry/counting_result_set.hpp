// A nanoflann result set that only counts the points inside a radius and stops the search
// once `enough` are seen: "are there at least k points within r?" without collecting them.
#pragma once

#include <cstddef>
#include <cstdint>

namespace gmpu {

template <class Distance>
struct CountingResultSet {
    Distance radius_sq;
    size_t enough;
    size_t count = 0;
    void init() {}
    void clear() { count = 0; }
    size_t size() const { return count; }
    bool full() const { return true; }
    bool addPoint(Distance dist, uint32_t) {
        if (dist < radius_sq) ++count;
        return count < enough;
    }
    Distance worstDist() const { return radius_sq; }
};

}  // namespace gmpu
