#include "strata/pipeline/Integrate.hpp"

#include <iomanip>
#include <optional>
#include <sstream>

#include "strata/core/Elapsed.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/NewSession.hpp"
#include "strata/pipeline/RankedSession.hpp"
#include "strata/pipeline/Register.hpp"

namespace strata::pipeline {

namespace {

// What comes before anything is written, in the one process or on rank 0: the odometry's poses
// (and `poses_out`) and the session's alignment; a refusal commits nothing. With both, the
// odometry starts in the map (OdometryStart: its first scan aligned, its poses the map's), and
// the session's alignment stays the identity; without odometry the session's scans are aligned
// as posed.
void PoseAndAlign(const store::MapStore& map, ScanSource& source, const IntegrateOptions& options,
                  IntegrateResult& result, store::SessionOptions& session) {
    if (options.odometry) {
        OdometryOptions odometry = *options.odometry;
        if (options.align) {
            odometry.start = OdometryStart{&map, map.Latest(), *options.align, options.on_aligned};
        }
        result.odometry = EstimateTrajectory(source, odometry);
        if (result.odometry->alignment) {
            result.alignment = result.odometry->alignment;
            session.notes = "odometry started in the map; first scan's alignment " +
                            AlignmentJson(*result.alignment).dump();
        }
        source =
            source.Posed(result.odometry->scans, result.odometry->poses, result.odometry->times_s);
        if (!options.poses_out.empty()) WriteTrajectory(options.poses_out, *result.odometry);
        return;
    }
    if (!options.align) return;
    const SourceCloud cloud =
        ReadSourceCloud(source, false, options.align->options, options.progress);
    const MapAlignment a =
        AlignToMap(map, map.Latest(), cloud, options.align->guess, options.align->options);
    if (options.on_aligned) options.on_aligned(a);
    RequireAccepted(a, "--align: the alignment of " + source.Describe());
    session.alignment = a.result.T_map_source.matrix();
    session.notes = "alignment " + AlignmentJson(a).dump();
    result.alignment = a;
}

// Reads, aligns and integrates into an open map; commits only when every scan went in.
IntegrateResult Run(OpenedMap& opened, const ScanSpec& scans, const IntegrateOptions& options) {
    store::MapStore& map = opened.map;
    ScanSource source = ScanSource::Open(scans, map.settings().origin);
    IntegrateResult result;
    result.created = opened.created;
    store::SessionOptions session;
    session.name = options.name;
    session.source = source.Describe();
    session.memory_budget_bytes = static_cast<size_t>(options.memory_budget_mb * 1e6);
    PoseAndAlign(map, source, options, result, session);
    if (options.on_start) options.on_start({map, source, opened.created, opened.rule});

    const auto start = core::Clock::now();
    NewSession writer(map, opened.rule, session);
    const char* stage = "integrating";
    ReportProgress(options.progress, stage, 0, source.size());
    for (size_t i = 0; i < source.size(); ++i) {
        const auto read_start = core::Clock::now();
        const core::Scan scan = source.Read(i);  // reader errors name their file already
        result.read_seconds += core::SecondsSince(read_start);
        (void)writer.Integrate(scan);
        ReportProgress(options.progress, stage, i + 1, source.size());
    }
    result.session = writer.Commit();
    result.seconds = core::SecondsSince(start);
    result.stats = writer.stats();
    result.map_tiles = map.Latest().tiles.size();
    return result;
}

// A 4x4 transform as text and back, every digit kept (for the other ranks).
std::string AlignmentText(const Eigen::Matrix4d& m) {
    std::ostringstream os;
    os << std::setprecision(17);
    for (int i = 0; i < 16; ++i) os << m.data()[i] << ' ';
    return os.str();
}

// The next 16 numbers of `is` as AlignmentText wrote them (`is` fails when they are not there).
Eigen::Matrix4d ReadMatrix(std::istream& is) {
    Eigen::Matrix4d m;
    for (int i = 0; i < 16; ++i) is >> m.data()[i];
    return m;
}

Eigen::Matrix4d AlignmentFromText(const std::string& text) {
    std::istringstream is(text);
    const Eigen::Matrix4d m = ReadMatrix(is);
    if (!is) throw FormatError("the session's alignment from rank 0 is not 16 numbers");
    return m;
}

// The odometry's poses as text and back, every digit kept: each pose's scan index, instant and
// 4x4 transform (for the other ranks, which integrate their share of the scans at them).
std::string TrajectoryText(const EstimatedTrajectory& t) {
    std::ostringstream os;
    os << std::setprecision(17) << t.poses.size() << ' ';
    for (size_t k = 0; k < t.poses.size(); ++k) {
        os << t.scans[k] << ' ' << t.times_s[k] << ' ' << AlignmentText(t.poses[k].matrix());
    }
    return os.str();
}

EstimatedTrajectory TrajectoryFromText(const std::string& text) {
    std::istringstream is(text);
    size_t n = 0;
    is >> n;
    EstimatedTrajectory t;
    for (size_t k = 0; is && k < n; ++k) {
        size_t scan = 0;
        double time = 0.0;
        is >> scan >> time;
        t.scans.push_back(scan);
        t.times_s.push_back(time);
        t.poses.emplace_back(ReadMatrix(is));
    }
    if (!is) throw FormatError("the odometry's poses from rank 0 are cut short");
    return t;
}

// The session on several ranks: rank 0 opens (or creates) the map for writing and aligns the
// session, the others open it for reading once it has; then every rank integrates its share.
IntegrateResult RunOnRanks(const std::filesystem::path& dir, const MapRequest& request,
                           const ScanSpec& scans, const IntegrateOptions& options) {
    const Ranks& ranks = *options.ranks;
    std::optional<OpenedMap> opened;
    OnEveryRank(ranks, [&] {
        if (ranks.root()) opened.emplace(OpenOrCreateMap(dir, request));
    });
    const bool created = ranks.Broadcast(ranks.root() && opened->created ? "1" : "0") == "1";
    try {
        OnEveryRank(ranks, [&] {
            if (ranks.root()) return;
            store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kRead);
            const integration::IntegrationConfig rule =
                ResolveRule(map.settings(), dir.string(), request.rule);
            opened.emplace(OpenedMap{std::move(map), created, rule});
        });
        store::MapStore& map = opened->map;
        std::optional<ScanSource> source;
        OnEveryRank(ranks, [&] { source.emplace(ScanSource::Open(scans, map.settings().origin)); });
        IntegrateResult result;
        result.created = created;
        store::SessionOptions session;
        session.name = options.name;
        session.source = source->Describe();
        session.memory_budget_bytes = static_cast<size_t>(options.memory_budget_mb * 1e6);
        // Rank 0 estimates the poses (one scan after another, the odometry's nature) and aligns;
        // every rank integrates at those poses with that transform.
        OnEveryRank(ranks, [&] {
            if (ranks.root()) PoseAndAlign(map, *source, options, result, session);
        });
        if (options.odometry) {
            const EstimatedTrajectory t = TrajectoryFromText(
                ranks.Broadcast(ranks.root() ? TrajectoryText(*result.odometry) : std::string()));
            if (!ranks.root()) source.emplace(source->Posed(t.scans, t.poses, t.times_s));
        }
        const std::string alignment = ranks.Broadcast(AlignmentText(session.alignment));
        session.alignment = AlignmentFromText(alignment);
        if (ranks.root() && options.on_start) {
            options.on_start({map, *source, created, opened->rule});
        }
        const auto start = core::Clock::now();
        const char* stage = "integrating";
        if (ranks.root()) ReportProgress(options.progress, stage, 0, source->size());
        const RankedSessionResult r = IntegrateOnRanks(
            map, source->size(), [&](size_t i) { return source->Read(i); }, opened->rule, session,
            ranks,
            [&](size_t done) { ReportProgress(options.progress, stage, done, source->size()); });
        result.session = r.session;
        result.stats = r.stats;
        result.steps = r.seconds;
        result.seconds = core::SecondsSince(start);
        result.map_tiles = map.Latest().tiles.size();
        return result;
    } catch (...) {
        // A map this command created holds nothing else: rank 0 removes it.
        if (created && ranks.root()) {
            opened.reset();
            std::error_code ignored;
            std::filesystem::remove_all(dir, ignored);
        }
        throw;
    }
}

}  // namespace

void IntegrateOptions::Validate() const {
    map.rule.Validate();
    if (!(memory_budget_mb >= 0.0)) throw InvalidArgumentError("--memory-budget must be >= 0");
    if (odometry) odometry->config.Validate();
    if (!poses_out.empty()) {
        if (!odometry) throw InvalidArgumentError("--poses-out needs --odometry");
        RequireTrajectoryFile(poses_out);
    }
}

IntegrateResult IntegrateSession(const std::filesystem::path& dir, const ScanSpec& given,
                                 const IntegrateOptions& options) {
    given.Validate();
    options.Validate();
    ScanSpec scans = given;
    if (options.odometry) scans.require_poses = false;  // the odometry estimates them
    const bool exists = store::MapStore::IsMap(dir);
    if (options.align && !exists) {
        throw InvalidArgumentError("--align needs a map to align to; " + dir.string() +
                                   " does not exist yet (integrate the first session without "
                                   "--align)");
    }
    MapRequest request = options.map;
    if (request.georeference_from.empty() && !scans.files.empty()) {
        request.georeference_from = scans.files.front();
    }
    if (options.ranks && options.ranks->size() > 1) return RunOnRanks(dir, request, scans, options);
    std::optional<OpenedMap> opened;
    opened.emplace(OpenOrCreateMap(dir, request));
    const bool created = opened->created;
    try {
        return Run(*opened, scans, options);
    } catch (...) {
        // A map this call created holds nothing else: leave no empty map behind.
        if (created) {
            opened.reset();  // closes the map first
            std::error_code ignored;
            std::filesystem::remove_all(dir, ignored);
        }
        throw;
    }
}

}  // namespace strata::pipeline
