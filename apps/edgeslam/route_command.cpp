// `edgeslam route make|list|rm`: navigation routes saved with a stored map (paper Sec. VI, the
// robot study): checkpoints every N m along a mapping session's keyframe path, or given positions.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "commands.h"
#include "io/frame_range.h"
#include "map_store_option.h"
#include "nav/route_making.h"
#include "store/store_error.h"
#include "store/stored_map_loader.h"

namespace edgeslam::cli {
namespace {

struct RouteCommandOptions {
  std::string maps;
  std::string map;
  std::string name;
  double spacing_m = 0.5;
  std::string frames;  // A-B of the mapping session
  std::filesystem::path positions;
  bool json = false;
};

RouteRecord makeFromKeyFrames(MapStore& store, const RouteCommandOptions& o) {
  auto stored = store.loadMap(o.map);
  if (!stored) throw StoreError(store.location() + ": no map '" + o.map + "'");
  const StoredSession* session = latestSessionWithKeyFrames(*stored);
  if (session == nullptr) {
    throw StoreError(store.location() + ": map '" + o.map + "' has no keyframes");
  }
  RouteAlongKeyFramesOptions options;
  options.spacing_m = o.spacing_m;
  if (!o.frames.empty()) {
    const FrameRange range = parseFrameRange(o.frames);
    options.first_frame = range.first;
    options.last_frame = range.last;
  }
  if (session->info.sensor == Sensor::kMonocular) {
    spdlog::warn(
        "map '{}' is monocular: it has no metric scale, so --every ({} m) is in the map's units",
        o.map, o.spacing_m);
  }
  return routeAlongKeyFrames(*session, options);
}

RouteRecord makeFromPositions(MapStore& store, const RouteCommandOptions& o) {
  auto stored = store.loadMap(o.map);
  if (!stored) throw StoreError(store.location() + ": no map '" + o.map + "'");
  std::ifstream in(o.positions);
  if (!in) throw std::runtime_error(o.positions.string() + ": cannot be read");
  std::stringstream text;
  text << in.rdbuf();
  RouteRecord route;
  try {
    route.checkpoints = parseCheckpointPositions(text.str());
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(o.positions.string() + ": " + e.what());
  }
  const StoredSession* session = latestSessionWithKeyFrames(*stored);
  if (session != nullptr) route.up = upOfKeyFrames(session->keyframes);
  route.source = "positions from " + o.positions.filename().string();
  return route;
}

nlohmann::json routeJson(const RouteRecord& route) {
  nlohmann::json checkpoints = nlohmann::json::array();
  for (const Eigen::Vector3d& c : route.checkpoints) checkpoints.push_back({c.x(), c.y(), c.z()});
  double length = 0.0;
  for (std::size_t i = 1; i < route.checkpoints.size(); ++i) {
    length += (route.checkpoints[i] - route.checkpoints[i - 1]).norm();
  }
  return {{"name", route.name},
          {"source", route.source},
          {"spacing_m", route.spacing_m},
          {"length_m", length},
          {"up", {route.up.x(), route.up.y(), route.up.z()}},
          {"checkpoints", checkpoints}};
}

int makeRoute(const RouteCommandOptions& o) {
  auto store = openMapStore(storeDirectory(o.maps), MapStoreAccess::kEdit);
  RouteRecord route =
      o.positions.empty() ? makeFromKeyFrames(*store, o) : makeFromPositions(*store, o);
  route.name = o.name;
  store->saveRoute(o.map, route);
  const nlohmann::json made = routeJson(route);
  if (o.json) {
    fmt::print("{}\n", made.dump(2));
  } else {
    fmt::print("route '{}' on map '{}': {} checkpoints over {:.2f} m ({})\n", route.name, o.map,
               route.checkpoints.size(), made["length_m"].get<double>(), route.source);
  }
  return 0;
}

int listRoutes(const RouteCommandOptions& o) {
  auto store = openMapStore(storeDirectory(o.maps), MapStoreAccess::kRead);
  if (!store->mapInfo(o.map)) throw StoreError(store->location() + ": no map '" + o.map + "'");
  const std::vector<RouteRecord> routes = store->listRoutes(o.map);
  if (o.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const RouteRecord& r : routes) out.push_back(routeJson(r));
    fmt::print("{}\n", nlohmann::json{{"map", o.map}, {"routes", out}}.dump(2));
    return 0;
  }
  if (routes.empty()) fmt::print("map '{}' has no routes\n", o.map);
  for (const RouteRecord& r : routes) {
    fmt::print("{:<20} {:>4} checkpoints  {}\n", r.name, r.checkpoints.size(), r.source);
  }
  return 0;
}

int removeRoute(const RouteCommandOptions& o) {
  auto store = openMapStore(storeDirectory(o.maps), MapStoreAccess::kEdit);
  if (!store->removeRoute(o.map, o.name)) {
    throw StoreError(store->location() + ": map '" + o.map + "' has no route '" + o.name + "'");
  }
  spdlog::info("route '{}' removed from map '{}'", o.name, o.map);
  return 0;
}

void addRouteCommand(CLI::App& app) {
  auto o = std::make_shared<RouteCommandOptions>();
  auto* cmd = app.add_subcommand("route", "Navigation routes on a stored map: make, list, rm");
  cmd->require_subcommand(1);

  auto* make = cmd->add_subcommand(
      "make",
      "Make a route on a map: checkpoints every --every m along its latest mapping session's "
      "keyframe path (optionally only --frames A-B of it), or the positions in --positions");
  make->add_option("name", o->name, "Route name (a route of that name is replaced)")->required();
  make->add_option("--map", o->map, "The stored map")->required();
  addMapsOption(make, o->maps);
  make->add_option("--every", o->spacing_m, "Spacing of checkpoints along the path, metres")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  make->add_option("--frames", o->frames,
                   "Only keyframes the mapping session made from these frames (A-B, inclusive)");
  auto* positions = make->add_option("--positions", o->positions,
                                     "A text file of checkpoints, one \"x y z\" per line, in the "
                                     "map's frame (instead of the keyframe path)");
  positions->excludes(make->get_option("--frames"));
  make->add_flag("--json", o->json, "Print the route as one JSON object");
  make->callback([o] { exitCode() = makeRoute(*o); });

  auto* list = cmd->add_subcommand("list", "List a map's routes");
  list->add_option("--map", o->map, "The stored map")->required();
  addMapsOption(list, o->maps);
  list->add_flag("--json", o->json, "One JSON object, with every checkpoint");
  list->callback([o] { exitCode() = listRoutes(*o); });

  auto* rm = cmd->add_subcommand("rm", "Remove a route from a map");
  rm->add_option("name", o->name, "Route name")->required();
  rm->add_option("--map", o->map, "The stored map")->required();
  addMapsOption(rm, o->maps);
  rm->callback([o] { exitCode() = removeRoute(*o); });
}

const CommandRegistration kRouteCommandRegistration{27, addRouteCommand};

}  // namespace
}  // namespace edgeslam::cli
