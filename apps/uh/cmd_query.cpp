// uh query A.ist B.ist --poses POSES.csv [--out RESULTS.csv] [--json] [--budget-us N]
// Per pose: the packings' overlap volume, the direction of the force the default (gradient) law
// puts on B, the overlapping pairs, the separation when apart, the time, and the coverage-calibrated
// volume estimate.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "poses_csv.hpp"
#include "uh/collette/distance_query.hpp"
#include "uh/collette/ist_file.hpp"
#include "uh/collette/time_critical_query.hpp"
#include "uh/collette/volume_query.hpp"
#include "uh/core/atomic_file_writer.hpp"

namespace uh::cli {
namespace {

struct QueryArgs {
  std::string a;
  std::string b;
  std::string poses;
  std::string out;
  bool json = false;
  double budget_us = 0.0;
  double coherence_skin = 0.0;  // mesh units; 0 = traverse for every pose
};

struct QueryRow {
  std::string id;
  double volume = 0.0;
  double volume_estimate = 0.0;  // volume / (coverage_a * coverage_b): estimate of the meshes' overlap
  Vec3
      direction{};  // of the force the default (gradient) law puts on B: -grad of the overlap volume; 0 apart
  std::int64_t pairs = 0;
  double distance = 0.0;
  double time_us = 0.0;
};

constexpr const char* kCsvHeader = "id,volume,nx,ny,nz,pairs,distance,time_us,volume_estimate";

std::string csv_line(const QueryRow& r) {
  return fmt::format("{},{:.9g},{:.9g},{:.9g},{:.9g},{},{:.9g},{:.3f},{:.9g}", r.id, r.volume, r.direction.x,
                     r.direction.y, r.direction.z, r.pairs, r.distance, r.time_us, r.volume_estimate);
}

// An existing results file is replaced only by a complete new one.
Status write_results_csv(const std::filesystem::path& path, const std::vector<QueryRow>& rows) {
  auto file = AtomicFileWriter::create(path);
  if (!file) return file.error();
  std::ostream& out = file->stream();
  out << kCsvHeader << '\n';
  for (const QueryRow& r : rows) out << csv_line(r) << '\n';
  return file->commit();
}

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size())));
  return values[std::clamp<std::size_t>(rank, 1, values.size()) - 1];
}

int run_query(const QueryArgs& args) {
  auto a = collette::load_ist(args.a);
  if (!a) return fail(a.error().message);
  auto b = collette::load_ist(args.b);
  if (!b) return fail(b.error().message);
  auto poses = read_poses_csv(args.poses);
  if (!poses) return fail(poses.error().message);

  // each packing fills a share (its coverage) of its mesh, so it meets about coverage_a * coverage_b
  // of the meshes' true overlap (docs/collette-queries.md, "Accuracy")
  const double calibration = a->meta.coverage * b->meta.coverage;
  collette::VolumeQuery volume_query({.coherence_skin = static_cast<float>(args.coherence_skin)});
  std::int64_t coherent_poses = 0;
  collette::TimeCriticalQuery time_critical_query;
  collette::DistanceQuery distance_query;
  const collette::TimeCriticalBudget budget{.max_seconds = args.budget_us * 1e-6};
  std::vector<QueryRow> rows;
  rows.reserve(poses->size());
  for (const PoseRow& pose : *poses) {
    QueryRow row{.id = pose.id};
    const auto start = std::chrono::steady_clock::now();
    if (args.budget_us > 0.0) {
      const auto& r = time_critical_query.run(a->tree, b->tree, pose.b_in_a, budget);
      row.volume = r.volume_estimate;
      row.direction = normalized(-r.volume_gradient);
      row.pairs = r.stats.overlapping_pairs;
    } else {
      const auto& r = volume_query.run(a->tree, b->tree, pose.b_in_a);
      row.volume = r.total_volume;
      row.direction = normalized(-r.volume_gradient);
      row.pairs = r.stats.overlapping_pairs;
      coherent_poses += r.reused_candidates ? 1 : 0;
    }
    if (row.volume <= 0.0) row.distance = distance_query.run(a->tree, b->tree, pose.b_in_a).distance;
    row.time_us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
    if (calibration > 0.0) row.volume_estimate = row.volume / calibration;
    rows.push_back(std::move(row));
  }

  if (!args.out.empty())
    if (auto written = write_results_csv(args.out, rows); !written) return fail(written.error().message);

  std::vector<double> times;
  for (const QueryRow& r : rows) times.push_back(r.time_us);
  if (args.json) {
    nlohmann::json results = nlohmann::json::array();
    for (const QueryRow& r : rows)
      results.push_back({{"id", r.id},
                         {"volume", r.volume},
                         {"nx", r.direction.x},
                         {"ny", r.direction.y},
                         {"nz", r.direction.z},
                         {"pairs", r.pairs},
                         {"distance", r.distance},
                         {"time_us", r.time_us},
                         {"volume_estimate", r.volume_estimate}});
    nlohmann::json j = {{"a", args.a},
                        {"b", args.b},
                        {"poses", rows.size()},
                        {"mode", args.budget_us > 0.0 ? "time-critical" : "exact"},
                        {"coverage", {a->meta.coverage, b->meta.coverage}},
                        {"time_us", {{"median", percentile(times, 0.5)}, {"p99", percentile(times, 0.99)},
                                     {"max", percentile(times, 1.0)}}},
                        {"results", results}};
    if (args.budget_us > 0.0) j["budget_us"] = args.budget_us;
    if (args.coherence_skin > 0.0) j["coherence"] = {{"skin", args.coherence_skin}, {"reused_poses", coherent_poses}};
    if (!args.out.empty()) j["out"] = args.out;
    std::printf("%s\n", j.dump(2).c_str());
  } else if (args.out.empty()) {
    std::printf("%s\n", kCsvHeader);
    for (const QueryRow& r : rows) std::printf("%s\n", csv_line(r).c_str());
  } else {
    std::printf("%zu poses -> %s; time_us median %.1f, p99 %.1f, max %.1f\n", rows.size(), args.out.c_str(),
                percentile(times, 0.5), percentile(times, 0.99), percentile(times, 1.0));
  }
  return 0;
}

}  // namespace

void add_query_command(CLI::App& app, CommandRunner& runner) {
  static QueryArgs args;
  auto* q = app.add_subcommand("query",
                               "intersection volume, force direction and distance of B against A per pose");
  q->add_option("a", args.a, "A.ist")->required()->check(CLI::ExistingFile);
  q->add_option("b", args.b, "B.ist")->required()->check(CLI::ExistingFile);
  q->add_option("--poses", args.poses, "CSV id,tx,ty,tz,qw,qx,qy,qz: pose of B's mesh frame in A's")->required()->check(CLI::ExistingFile);
  q->add_option("--out", args.out,
                "write id,volume,nx,ny,nz,pairs,distance,time_us,volume_estimate to this CSV");
  q->add_flag("--json", args.json, "print a JSON summary (median, p99, max time_us) with the results");
  q->add_option("--budget-us", args.budget_us, "time-critical query with this budget per pose [us]")->check(CLI::PositiveNumber);
  q->add_option("--coherence-skin", args.coherence_skin,
                "poses form a path: keep candidate pairs this far apart [mesh units] and reuse them while B moves less")
      ->check(CLI::NonNegativeNumber);
  q->callback([&runner] { runner = [] { return run_query(args); }; });
}

}  // namespace uh::cli
