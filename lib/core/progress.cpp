#include "core/progress.hpp"

#include <algorithm>

namespace gmpu {

namespace {
const char *stage_name(gmpu_stage stage) {
    switch (stage) {
        case GMPU_STAGE_FIT: return "fit";
        case GMPU_STAGE_ORIENT: return "orient";
        case GMPU_STAGE_POLYGONIZE: return "polygonize";
        case GMPU_STAGE_READ: return "reading";
    }
    return "work";
}
}  // namespace

void Progress::report(double fraction, bool force) {
    if (!fn_ || cancelled()) return;
    auto now = std::chrono::steady_clock::now();
    if (!force && now - last_report_ < kReportInterval) return;
    last_report_ = now;
    // Promise the caller a non-decreasing fraction in [0, 1].
    last_fraction_ = std::clamp(std::max(fraction, last_fraction_), 0.0, 1.0);
    if (fn_(user_, stage_, last_fraction_) != 0) cancel();
}

void Progress::throw_if_cancelled() const {
    if (cancelled())
        throw Error(GMPU_ERROR_CANCELLED,
                    std::string(stage_name(stage_)) + " cancelled by the progress callback");
}


}  // namespace gmpu
