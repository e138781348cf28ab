#include "strata/pipeline/NewSession.hpp"

#include <stdexcept>
#include <string>

#include "strata/core/Error.hpp"

namespace strata::pipeline {

namespace {

// The same kind of error with `prefix` before its message: callers branch on the kind.
[[noreturn]] void RethrowPrefixed(const std::exception& e, const std::string& prefix) {
    const std::string m = prefix + e.what();
    if (dynamic_cast<const RefusedError*>(&e)) throw RefusedError(m);
    if (dynamic_cast<const InvalidArgumentError*>(&e)) throw InvalidArgumentError(m);
    if (dynamic_cast<const std::invalid_argument*>(&e)) throw InvalidArgumentError(m);
    if (dynamic_cast<const FormatError*>(&e)) throw FormatError(m);
    if (dynamic_cast<const NotFoundError*>(&e)) throw NotFoundError(m);
    if (dynamic_cast<const MapLockedError*>(&e)) throw MapLockedError(m);
    if (dynamic_cast<const IoError*>(&e)) throw IoError(m);
    throw Error(m);
}

}  // namespace

NewSession::NewSession(store::MapStore& map, const integration::IntegrationConfig& rule,
                       store::SessionOptions options)
    : writer_(std::make_unique<store::SessionWriter>(map, rule, std::move(options))) {}

integration::ScanUpdate NewSession::Integrate(const core::Scan& scan) {
    if (committed_) throw InvalidArgumentError("the session is committed already");
    integration::ScanUpdate update;
    try {
        update = writer_->Integrate(scan);
    } catch (const std::exception& e) {
        RethrowPrefixed(e, "scan " + std::to_string(scans_) + " (" + scan.source + "): ");
    }
    ++scans_;
    return update;
}

store::SessionRecord NewSession::Commit() {
    if (committed_) throw InvalidArgumentError("the session is committed already");
    committed_ = true;  // a failed commit leaves nothing to retry: the writer cleans up
    return writer_->Commit();
}

}  // namespace strata::pipeline
