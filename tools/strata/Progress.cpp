#include "Progress.hpp"

#include <unistd.h>

#include <cstdio>
#include <memory>

namespace strata::tools {

Progress::Progress(std::string label, size_t total)
    : label_(std::move(label)), total_(total), enabled_(::isatty(STDERR_FILENO) == 1) {}

Progress::~Progress() {
    if (enabled_) std::fputc('\n', stderr);
}

void Progress::Advance(size_t n) {
    done_ += n;
    if (enabled_) Draw();
}

void Progress::Update(size_t done, size_t total) {
    done_ = done;
    total_ = total;
    if (enabled_) Draw();
}

void Progress::Draw() const {
    constexpr int kWidth = 30;
    const double fraction = total_ ? static_cast<double>(done_) / static_cast<double>(total_) : 1.0;
    const int filled = static_cast<int>(fraction * kWidth);
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    std::fprintf(stderr, "\r%s [%.*s%*s] %zu/%zu %.1fs", label_.c_str(), filled,
                 "##############################", kWidth - filled, "", done_, total_, elapsed);
    std::fflush(stderr);
}

pipeline::ProgressCallback ProgressBars() {
    struct Bars {
        std::string stage;
        std::unique_ptr<Progress> bar;
    };
    auto bars = std::make_shared<Bars>();  // std::function copies its target
    return [bars](const pipeline::ProgressEvent& e) {
        if (!bars->bar || e.stage != bars->stage) {
            bars->bar.reset();  // ends the previous stage's line first
            bars->stage = e.stage;
            bars->bar = std::make_unique<Progress>(e.stage, e.total);
        }
        bars->bar->Update(e.done, e.total);
        if (e.done >= e.total) bars->bar.reset();
    };
}

}  // namespace strata::tools
