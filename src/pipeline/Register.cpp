#include "strata/pipeline/Register.hpp"

#include "strata/core/Error.hpp"
#include "strata/pipeline/MapAccess.hpp"
#include "strata/registration/SessionCloud.hpp"

namespace strata::pipeline {

SourceCloud ReadSourceCloud(const ScanSource& source, bool as_is, const AlignOptions& options,
                            const ProgressCallback& progress) {
    if (source.size() == 0) throw InvalidArgumentError("no scans to align");
    SourceCloud cloud;
    cloud.scans = source.size();
    if (as_is && source.size() == 1) {
        core::Scan scan = source.Read(0);
        cloud.single_scan = true;
        cloud.points = std::move(scan.points);
        return cloud;
    }
    registration::SessionCloudConfig cloud_config;
    cloud_config.min_range_m = options.min_range_m;
    cloud_config.max_range_m = options.max_range_m;
    registration::CloudAccumulator acc(cloud_config);
    const char* stage = "reading scans";
    ReportProgress(progress, stage, 0, source.size());
    for (size_t i = 0; i < source.size(); ++i) {
        acc.Add(source.Read(i));
        ReportProgress(progress, stage, i + 1, source.size());
    }
    cloud.points = acc.TakePoints();
    return cloud;
}

Registration RegisterScans(const store::MapStore& map, const RegisterOptions& options) {
    const ScanSource source = ScanSource::Open(options.scans, map.settings().origin);
    // A single scan without poses is registered as it is (its own frame); otherwise the scans
    // form a session in the frame of their poses.
    const SourceCloud cloud = ReadSourceCloud(source, options.scans.poses.empty(),
                                              options.align.options, options.progress);
    Registration r;
    r.alignment = AlignToMap(map, SelectSnapshot(map, options.as_of), cloud, options.align.guess,
                             options.align.options);
    r.source = source.Describe();
    r.scans = cloud.scans;
    r.single_scan = cloud.single_scan;
    return r;
}

nlohmann::json RegistrationJson(const Registration& r) {
    nlohmann::json j = AlignmentJson(r.alignment);
    j["source"] = r.source;
    j["scans"] = r.scans;
    return j;
}

}  // namespace strata::pipeline
