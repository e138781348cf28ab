// strata view: the map, its walls, vehicles, changes and history in a browser (docs/viewer.md).
#include <iostream>
#include <memory>

#include "Commands.hpp"
#include "HttpServer.hpp"
#include "StaticSite.hpp"
#include "ViewService.hpp"

namespace strata::tools {

namespace {

struct ViewArgs {
    std::string map;
    view::ServeOptions serve;
    std::string as_of;
    std::string html;
    size_t cache_mb = 512;
};

std::string Address(const std::string& bind, int port) {
    const std::string host = bind == "0.0.0.0" ? "127.0.0.1" : bind;
    return "http://" + (host.find(':') != std::string::npos ? "[" + host + "]" : host) + ":" +
           std::to_string(port) + "/";
}

void Run(const ViewArgs& args) {
    args.serve.Validate();
    const auto source = view::ViewSource::Open(args.map, args.as_of);
    view::ServiceOptions options;
    options.tile_cache_bytes = args.cache_mb << 20;
    const auto service =
        std::make_shared<const view::ViewService>(source, view::LoadWebAssets(), options);
    const view::ViewSnapshot& shown = source->snapshots().front();
    if (!args.html.empty()) {
        const view::StaticSiteReport report = view::WriteStaticSite(*service, args.html);
        std::cout << "wrote " << args.html << ": " << report.files << " files, "
                  << (report.bytes >> 20) << " MB (" << shown.tiles.size() << " tiles, "
                  << report.diffs << " session diffs); open " << args.html << "/index.html\n";
        return;
    }
    view::HttpServer server(service, args.serve);
    std::cout << "strata view: " << args.map << " (commit " << shown.commit << ", "
              << shown.tiles.size() << " tiles, " << shown.sessions.size()
              << (shown.sessions.size() == 1 ? " session" : " sessions") << "), read-only, at\n  "
              << Address(args.serve.bind, server.port()) << "\nCtrl-C stops.\n"
              << std::flush;
    if (args.serve.bind != "127.0.0.1" && args.serve.bind != "localhost" &&
        args.serve.bind != "::1") {
        std::cerr << "strata view: serving beyond this machine: anyone who reaches "
                  << args.serve.bind << " can read the map\n";
    }
    server.Run();
}

}  // namespace

void RegisterView(CLI::App& app) {
    auto args = std::make_shared<ViewArgs>();
    CLI::App* cmd = app.add_subcommand(
        "view",
        "Look at the map in a browser: voxels by class, height, session or slant; walls, "
        "vehicles, changes; a session timeline");
    cmd->footer(
        "Examples:\n"
        "  strata view strata-demo/map                 # then open the address it prints\n"
        "  strata view city.strata --port 0 --as-of 3  # any free port; the map after session 3\n"
        "  strata view city.strata --html city-view/   # a folder that opens from disk");
    cmd->add_option("MAP", args->map, "Map directory")->required();
    cmd->add_option("--port", args->serve.port, "Port (0: any free one)")->capture_default_str();
    cmd->add_option("--bind", args->serve.bind,
                    "Address to listen on (0.0.0.0 serves to the network)")
        ->capture_default_str();
    cmd->add_option("--as-of", args->as_of, "Show the map right after this session first");
    cmd->add_option("--html", args->html, "Write the page and its data to this folder instead");
    cmd->add_option("--cache-mb", args->cache_mb, "Decoded tiles kept in memory (MB)")
        ->capture_default_str();
    cmd->callback([args] { Run(*args); });
}

}  // namespace strata::tools
