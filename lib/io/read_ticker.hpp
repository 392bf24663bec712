// Progress of reading one file (gmpu_points_read_with): each pass over the file (a count of
// its lines or its header, then the parse) takes a share of the fraction, and every poll may
// end the read with CANCELLED. Without a Progress it costs a null test.
#pragma once

#include "core/progress.hpp"

namespace gmpu::io::detail {

struct ReadTicker {
    Progress *progress = nullptr;
    double begin = 0.0, share = 1.0;  // the current pass's part of the whole read

    void pass(double pass_begin, double pass_share) { begin = pass_begin, share = pass_share; }
    // `fraction` of the current pass is done.
    void at(double fraction) const {
        if (progress) progress->poll(begin + share * fraction);
    }
};

}  // namespace gmpu::io::detail
