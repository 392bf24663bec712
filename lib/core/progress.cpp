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

void Progress::report_overall(double fraction, bool force) {
    Shared &s = *shared_;
    if (!s.fn || cancelled()) return;
    // Fraction 1 is the stage's final report alone (forced, once the result is ready): a step
    // ending on the stage's last slice would otherwise say 1 before it, and callers that act
    // on 1 would act twice.
    if (!force && fraction >= 1.0) return;
    auto now = std::chrono::steady_clock::now();
    if (!force && now - s.last_report < kReportInterval) return;
    s.last_report = now;
    // Promise the caller a non-decreasing fraction in [0, 1].
    s.last_fraction = std::clamp(std::max(fraction, s.last_fraction), 0.0, 1.0);
    if (s.fn(s.user, s.stage, s.last_fraction) != 0) cancel();
}

void Progress::throw_if_cancelled() const {
    if (cancelled())
        throw Error(GMPU_ERROR_CANCELLED,
                    std::string(stage_name(shared_->stage)) + " cancelled by the progress callback");
}


}  // namespace gmpu
