// `edgeslam map list|info|export|rm`: the maps an edge store holds.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <ctime>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "commands.h"
#include "map/map.h"
#include "map_store_option.h"
#include "mapping/local_mapper.h"
#include "store/map_export.h"
#include "store/store_error.h"
#include "store/stored_map_loader.h"
#include "util/timing_stats.h"
#include "vocabulary_option.h"

namespace edgeslam::cli {
namespace {

struct MapCommandOptions {
  std::string maps;
  std::string name;
  bool json = false;
  bool load = false;
  std::string vocabulary = "none";  // --load: the server's --vocab, for the bags of words
  std::string format;
  std::filesystem::path out;
};

// CPU time of the whole process (every thread), in ms: on a shared machine the wall time of a load
// is mostly waiting for a core.
double processCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) / 1e6;
}

std::string isoTime(double unix_seconds) {
  if (unix_seconds <= 0.0) return "";
  const auto t = static_cast<std::time_t>(unix_seconds);
  std::tm utc{};
  gmtime_r(&t, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

nlohmann::json summaryJson(const MapSummary& m) {
  return {{"name", m.name},
          {"keyframes", m.keyframes},
          {"points", m.points},
          {"sessions", m.sessions},
          {"metric", m.metric},
          {"bytes", m.bytes},
          {"created", isoTime(m.created)},
          {"updated", isoTime(m.updated)},
          {"extent_m",
           {{"min", {m.extent_min.x(), m.extent_min.y(), m.extent_min.z()}},
            {"max", {m.extent_max.x(), m.extent_max.y(), m.extent_max.z()}}}}};
}

std::unique_ptr<MapStore> openForReading(const MapCommandOptions& o, MapStoreAccess access) {
  return openMapStore(storeDirectory(o.maps), access);
}

[[noreturn]] void noSuchMap(const MapStore& store, const std::string& name) {
  throw StoreError(store.location() + ": no map '" + name + "'");
}

int listMaps(const MapCommandOptions& o) {
  auto store = openForReading(o, MapStoreAccess::kRead);
  const auto maps = store->listMaps();
  if (o.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const MapSummary& m : maps) out.push_back(summaryJson(m));
    fmt::print("{}\n", nlohmann::json{{"store", store->location()}, {"maps", out}}.dump(2));
    return 0;
  }
  fmt::print("{:<40} {:>9} {:>9} {:>8} {:>12}  {}\n", "map", "keyframes", "points", "sessions",
             "bytes", "updated");
  for (const MapSummary& m : maps) {
    fmt::print("{:<40} {:>9} {:>9} {:>8} {:>12}  {}\n", m.name, m.keyframes, m.points, m.sessions,
               m.bytes, isoTime(m.updated));
  }
  return 0;
}

int mapInfo(const MapCommandOptions& o) {
  auto store = openForReading(o, MapStoreAccess::kRead);
  const auto info = store->mapInfo(o.name);
  if (!info) noSuchMap(*store, o.name);
  nlohmann::json out = summaryJson(*info);
  nlohmann::json routes = nlohmann::json::array();
  for (const RouteRecord& route : store->listRoutes(o.name)) routes.push_back(route.name);
  out["routes"] = routes;
  if (o.load) {
    // As a server resuming the map would: records read, then the maps rebuilt (covisibility too)
    // and, with a vocabulary, every keyframe given its bag of words (stored, else computed).
    std::shared_ptr<const Vocabulary> vocabulary;
    {
      // Logs go to stdout: with --json only the object may be there.
      const spdlog::level::level_enum level = spdlog::get_level();
      if (o.json) spdlog::set_level(spdlog::level::err);
      vocabulary = loadVocabulary(o.vocabulary);
      spdlog::set_level(level);
    }
    const double cpu_start_ms = processCpuMs();
    Stopwatch read_timer;
    auto stored = store->loadMap(o.name);
    const double read_ms = read_timer.elapsedMs();
    double rebuild_ms = 0.0, places_ms = 0.0;
    std::size_t keyframes = 0, points = 0, places_stored = 0, places_computed = 0;
    std::optional<std::uint64_t> checksum;
    // Kept until the figures are taken: a server keeps the map it loaded (freeing ~100k points
    // took ~0.5 s of the 1000-keyframe map's figure).
    std::vector<std::unique_ptr<Map>> maps;
    for (StoredSession& session : stored->sessions) {
      Map& map = *maps.emplace_back(std::make_unique<Map>());
      Stopwatch rebuild_timer;
      loadStoredSessionTakingFeatures(session, map);
      rebuild_ms += rebuild_timer.elapsedMs();
      if (vocabulary != nullptr && !vocabulary->empty()) {
        Stopwatch places_timer;
        if (!checksum) checksum = vocabulary->checksum();
        const int depth = LocalMapperOptions{}.direct_index_depth;
        places_stored += attachStoredPlaces(session, map, *vocabulary, *checksum, depth).attached;
        places_computed += describeKeyFrames(map, *vocabulary, depth);
        places_ms += places_timer.elapsedMs();
      }
      MutexLock lock(map.updateMutex());
      keyframes += map.keyFrameCount();
      points += map.pointCount();
    }
    out["load"] = {{"read_ms", read_ms},
                   {"rebuild_ms", rebuild_ms},
                   {"bow_ms", places_ms},
                   {"bow_stored", places_stored},
                   {"bow_computed", places_computed},
                   {"load_ms", read_timer.elapsedMs()},
                   {"load_cpu_ms", processCpuMs() - cpu_start_ms},
                   {"keyframes", keyframes},
                   {"points", points}};
  }
  if (o.json) {
    fmt::print("{}\n", out.dump(2));
    return 0;
  }
  fmt::print("map {} in {}\n", info->name, store->location());
  fmt::print("  {} keyframes, {} points, {} session(s), {} bytes\n", info->keyframes, info->points,
             info->sessions, info->bytes);
  fmt::print("  created {}, updated {}\n", isoTime(info->created), isoTime(info->updated));
  if (!routes.empty()) fmt::print("  routes: {}\n", fmt::join(routes, ", "));
  if (o.load) {
    fmt::print(
        "  loaded in {:.1f} ms, {:.1f} ms of CPU (read {:.1f} ms, rebuilt {:.1f} ms, bags of words "
        "{:.1f} ms: {} stored, {} computed)\n",
        out["load"]["load_ms"].get<double>(), out["load"]["load_cpu_ms"].get<double>(),
        out["load"]["read_ms"].get<double>(), out["load"]["rebuild_ms"].get<double>(),
        out["load"]["bow_ms"].get<double>(), out["load"]["bow_stored"].get<std::size_t>(),
        out["load"]["bow_computed"].get<std::size_t>());
  }
  return 0;
}

int exportMap(const MapCommandOptions& o) {
  auto store = openForReading(o, MapStoreAccess::kRead);
  const auto map = store->loadMap(o.name);
  if (!map) noSuchMap(*store, o.name);
  if (o.format == "tum") {
    exportTum(*map, o.out);
  } else if (o.format == "ply") {
    exportPly(*map, o.out);
  } else {
    exportColmap(*map, o.out);
  }
  spdlog::info("map '{}' exported as {} to {}", o.name, o.format, o.out.string());
  return 0;
}

int removeMap(const MapCommandOptions& o) {
  auto store = openForReading(o, MapStoreAccess::kEdit);
  if (!store->removeMap(o.name)) noSuchMap(*store, o.name);
  spdlog::info("map '{}' removed from {}", o.name, store->location());
  return 0;
}

void addMapCommand(CLI::App& app) {
  auto o = std::make_shared<MapCommandOptions>();
  auto* cmd = app.add_subcommand("map", "The maps an edge store keeps: list, info, export, rm");
  cmd->require_subcommand(1);

  auto* list = cmd->add_subcommand("list", "List the store's maps");
  addMapsOption(list, o->maps);
  list->add_flag("--json", o->json, "One JSON object");
  list->callback([o] { exitCode() = listMaps(*o); });

  auto* info = cmd->add_subcommand("info", "One map's size and times");
  info->add_option("name", o->name, "Map name")->required();
  addMapsOption(info, o->maps);
  info->add_flag("--json", o->json, "One JSON object");
  info->add_flag("--load", o->load, "Also load the map as a server would and time it");
  info->add_option("--vocab", o->vocabulary,
                   "With --load: the server's vocabulary, for the keyframes' bags of words (stored "
                   "ones are used, the others computed); default none, \"\" = as run's default")
      ->capture_default_str();
  info->callback([o] { exitCode() = mapInfo(*o); });

  auto* exp = cmd->add_subcommand("export", "Write a map as TUM keyframes, PLY points or COLMAP");
  exp->add_option("name", o->name, "Map name")->required();
  addMapsOption(exp, o->maps);
  exp->add_option("--format", o->format,
                  "tum (keyframe trajectory), ply (points), colmap "
                  "(text model folder)")
      ->required()
      ->check(CLI::IsMember({"tum", "ply", "colmap"}));
  exp->add_option("--out", o->out, "Output file (tum, ply) or folder (colmap)")->required();
  exp->callback([o] { exitCode() = exportMap(*o); });

  auto* rm = cmd->add_subcommand("rm", "Remove a map (not while a server writes to the store)");
  rm->add_option("name", o->name, "Map name")->required();
  addMapsOption(rm, o->maps);
  rm->callback([o] { exitCode() = removeMap(*o); });
}

const CommandRegistration kMapCommandRegistration{25, addMapCommand};

}  // namespace
}  // namespace edgeslam::cli
