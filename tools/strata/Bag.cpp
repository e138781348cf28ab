// strata bag info: what a robot recording (a ROS 1 bag or an MCAP file) holds, as `rosbag info`
// and `ros2 bag info` print it, with its tf tree.
#include <cstdint>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "Commands.hpp"
#include "strata/pipeline/Recordings.hpp"

namespace strata::tools {

namespace {

void PrintText(const nlohmann::json& j) {
    std::cout << "path         " << j["path"].get<std::string>() << "\n"
              << "format       " << j["format"].get<std::string>()
              << (j["indexed"].get<bool>() ? "" : " (no index: the recorder did not close it)")
              << "\n"
              << "size         " << std::fixed << std::setprecision(1)
              << j["bytes"].get<uint64_t>() / 1e6 << " MB\n"
              << "compression  " << j["compression"].get<std::string>() << " ("
              << j["chunks"].get<uint64_t>() << (j["chunks"] == 1 ? " chunk)\n" : " chunks)\n")
              << "start        " << j["start"].get<std::string>() << "\n"
              << "end          " << j["end"].get<std::string>() << "\n"
              << "duration     " << std::setprecision(3) << j["duration_s"].get<double>() << " s\n"
              << "messages     " << j["messages"].get<uint64_t>() << "\n"
              << "topics:\n";
    for (const auto& t : j["topics"]) {
        std::cout << "  " << std::left << std::setw(32) << t["name"].get<std::string>() << " "
                  << std::right << std::setw(8) << t["messages"].get<uint64_t>() << " msgs  "
                  << t["type"].get<std::string>() << "\n";
    }
    std::cout << "tf tree (" << j["frames"].size() << " frames):\n";
    for (const auto& e : j["tf_edges"]) {
        std::cout << "  " << e["parent"].get<std::string>() << " -> "
                  << e["child"].get<std::string>();
        if (e["static"].get<bool>()) {
            std::cout << " (static)\n";
        } else {
            std::cout << " (" << e["samples"].get<uint64_t>() << " poses, "
                      << e["first"].get<std::string>() << " .. " << e["last"].get<std::string>()
                      << ")\n";
        }
    }
}

}  // namespace

void RegisterBag(CLI::App& app) {
    CLI::App* bag = app.add_subcommand("bag", "Robot recordings (ROS 1 .bag, MCAP)");
    bag->require_subcommand(1);
    auto file = std::make_shared<std::string>();
    auto json = std::make_shared<bool>(false);
    CLI::App* info = bag->add_subcommand(
        "info", "Show a recording's topics, message counts, time span and tf tree");
    info->footer(
        "Examples:\n  strata bag info drive.bag\n  strata bag info drive.bag --json | jq .topics");
    info->add_option("FILE", *file, "The recording")->required();
    info->add_flag("--json", *json, "Print JSON");
    info->callback([file, json] {
        const nlohmann::json j = pipeline::DescribeRecording(*file);
        if (*json) {
            std::cout << j.dump(2) << "\n";
        } else {
            PrintText(j);
        }
    });
}

}  // namespace strata::tools
