// The Unreal plugin's C API layer (UhApi.h's function list, UhSessionBuilder, UhConvert), compiled
// here with stand-ins for the few UE types it touches (ue_stubs/) and run against the built libuh
// the way AHapticManager runs it: every function resolved by name, the level's scene built (a
// static mesh's triangles, a watcher, a scene object to remove that is not there), the session
// started with the haptic-tick hook, polled, stopped and closed. A libuh function or struct field
// the plugin names and the library no longer has fails here, not in an Unreal user's build.
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "UhApi.h"
#include "UhConvert.h"
#include "UhSessionBuilder.h"

namespace {

// libuh as the plugin's FUhApi::Get() loads it: the library the build made, every function the
// plugin lists resolved by name. Missing names are collected, not fatal, so one run lists them all.
struct LoadedApi {
  FUhApi api;
  std::vector<std::string> missing;
  std::string load_error;
};

const LoadedApi& loaded_api() {
  static const LoadedApi loaded = [] {
    LoadedApi out;
    const char* path = std::getenv("UH_LIBUH");
    void* handle = path != nullptr ? dlopen(path, RTLD_NOW | RTLD_LOCAL) : nullptr;
    if (handle == nullptr) {
      out.load_error = path == nullptr ? "UH_LIBUH is not set" : dlerror();
      return out;
    }
    // a function pointer from dlsym's object pointer without a cast ISO C++ leaves undefined
#define UH_TEST_RESOLVE(Name)                                              \
  if (void* symbol = dlsym(handle, #Name); symbol != nullptr) {            \
    std::memcpy(&out.api.Name, &symbol, sizeof symbol);                    \
  } else {                                                                 \
    out.missing.push_back(#Name);                                          \
  }
    UH_API_FUNCTIONS(UH_TEST_RESOLVE)
#undef UH_TEST_RESOLVE
    return out;
  }();
  return loaded;
}

const FUhApi& api() {
  const LoadedApi& loaded = loaded_api();
  EXPECT_TRUE(loaded.load_error.empty()) << loaded.load_error;
  EXPECT_TRUE(loaded.missing.empty());
  return loaded.api;
}

// the packing cache, kept between runs (the default scene's meshes take seconds to pack)
std::filesystem::path cache_dir() {
  const char* tmp = std::getenv("UH_TEST_TMP");  // set by ctest: the test's build folder
  const std::filesystem::path dir =
      (tmp != nullptr ? std::filesystem::path(tmp) : std::filesystem::temp_directory_path()) / "unreal-contract-cache";
  std::filesystem::create_directories(dir);
  return dir;
}

// A 2 cm cube beside the default scene's bunny, as a ColletteStaticMeshActor sends a static mesh
// (metres, counter-clockwise seen from outside).
FUhObjectSpec cube(const char* name) {
  FUhObjectSpec spec;
  spec.Name = name;
  const double h = 0.01;
  for (int i = 0; i < 8; ++i) {
    spec.Vertices.Add((i & 1) != 0 ? h : -h);
    spec.Vertices.Add((i & 2) != 0 ? h : -h);
    spec.Vertices.Add((i & 4) != 0 ? h : -h);
  }
  const int32 faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                              {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  for (const auto& face : faces)
    for (int32 index : face) spec.Indices.Add(index);
  spec.Position[0] = 0.2;
  spec.Spheres = 200;
  spec.bWatch = false;  // watched only because a volume names it
  return spec;
}

FUhSessionRequest level_request(const std::filesystem::path& cache) {
  FUhSessionRequest request;
  request.Objects.Add(cube("cube"));
  request.SceneObjectsToRemove.Add("no-such-object");
  request.Watched.Add("cube");
  request.bHasTool = true;  // a ForceComponent without a tool mesh: the scene's tool is kept
  request.CacheDir = cache.string().c_str();
  return request;
}

std::vector<std::filesystem::path> cached_cubes(const std::filesystem::path& cache) {
  std::vector<std::filesystem::path> out;
  for (const auto& entry : std::filesystem::directory_iterator(cache))
    if (entry.path().filename().string().rfind("cube-", 0) == 0) out.push_back(entry.path());
  return out;
}

// a native hook as a game's code adds it: counts the ticks it saw and keeps the newest tick count
struct TickCounter {
  std::atomic<int> calls{0};
  std::atomic<uint64> newest_tick{0};
  static void on_tick(void* user, const FUhTickState& state) {
    auto& self = *static_cast<TickCounter*>(user);
    self.calls.fetch_add(1, std::memory_order_relaxed);
    self.newest_tick.store(state.HapticTicks, std::memory_order_relaxed);
  }
};

}  // namespace

TEST(UnrealPluginContract, LibuhHasEveryFunctionThePluginResolves) {
  const LoadedApi& loaded = loaded_api();
  ASSERT_TRUE(loaded.load_error.empty()) << loaded.load_error;
  std::string missing;
  for (const std::string& name : loaded.missing) missing += name + " ";
  EXPECT_TRUE(loaded.missing.empty()) << "libuh lacks: " << missing;
  EXPECT_EQ(loaded.api.uh_api_version(), UH_API_VERSION);
}

TEST(UnrealPluginContract, BuildsStartsPollsAndStopsTheLevelsSession) {
  const FUhApi& uh = api();
  const std::filesystem::path cache = cache_dir();
  FUhSessionBuild build = UhBuildSession(uh, level_request(cache));
  ASSERT_NE(build.Session.bits, 0u) << *build.Error;
  // the missing scene object and the tool without a mesh are warnings, never a failed start
  ASSERT_EQ(build.Warnings.Num(), 2);
  EXPECT_TRUE(build.Warnings[0].Contains("no-such-object")) << *build.Warnings[0];
  EXPECT_TRUE(build.Warnings[1].Contains("tool")) << *build.Warnings[1];
  ASSERT_EQ(build.ObjectNames.Num(), 2);
  EXPECT_TRUE(build.ObjectNames.Contains("bunny"));
  EXPECT_TRUE(build.ObjectNames.Contains("cube"));

  // AddHapticTickHook twice: both hooks are called on the haptic thread through UhDispatchTick
  TickCounter first_hook, second_hook;
  FUhHapticHookTable table;
  table.Fns[0] = &TickCounter::on_tick;
  table.Users[0] = &first_hook;
  table.Fns[1] = &TickCounter::on_tick;
  table.Users[1] = &second_hook;
  table.Count = 2;
  FString error;
  ASSERT_TRUE(UhStartSession(uh, build.Session, &UhDispatchTick, &table, error)) << *error;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (second_hook.calls.load() < 100 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_GE(first_hook.calls.load(), 100);
  EXPECT_GE(second_hook.calls.load(), 100);
  EXPECT_GT(second_hook.newest_tick.load(), 0u);

  // the manager's Tick: the newest state and the event queue
  uh_state state{};
  state.struct_size = sizeof state;
  ASSERT_EQ(uh.uh_session_poll(build.Session, &state), UH_OK) << *uh.LastError();
  EXPECT_GT(state.haptic_ticks, 0u);
  uh_contact_event event{};
  event.struct_size = sizeof event;
  int32 has_event = 1;
  while (has_event != 0) ASSERT_EQ(uh.uh_session_poll_event(build.Session, &event, &has_event), UH_OK);

  const double pose[3] = {0.2, 0.0, 0.01};
  const double rotation[4] = {1, 0, 0, 0};
  EXPECT_EQ(uh.uh_session_set_object_pose(build.Session, 1, pose, rotation), UH_OK) << *uh.LastError();

  // StopHaptics: stop, report, the last state carries the zero force sent
  ASSERT_EQ(uh.uh_session_stop(build.Session), UH_OK) << *uh.LastError();
  const char* report = nullptr;
  ASSERT_EQ(uh.uh_session_report_json(build.Session, &report), UH_OK) << *uh.LastError();
  EXPECT_EQ(report[0], '{');
  ASSERT_EQ(uh.uh_session_poll(build.Session, &state), UH_OK);
  EXPECT_EQ(state.force[0], 0.0);
  EXPECT_EQ(state.force[1], 0.0);
  EXPECT_EQ(state.force[2], 0.0);
  uh.uh_session_destroy(build.Session);
}

TEST(UnrealPluginContract, CachesAStaticMeshsPackingAndRepacksADamagedOne) {
  const FUhApi& uh = api();
  const std::filesystem::path cache = cache_dir();
  for (const std::filesystem::path& old : cached_cubes(cache)) std::filesystem::remove(old);
  FUhSessionBuild first = UhBuildSession(uh, level_request(cache));
  ASSERT_NE(first.Session.bits, 0u) << *first.Error;
  uh.uh_session_destroy(first.Session);
  const std::vector<std::filesystem::path> cached = cached_cubes(cache);
  ASSERT_EQ(cached.size(), 1u);

  std::ofstream(cached[0], std::ios::binary | std::ios::trunc) << "not a tree";
  FUhSessionBuild second = UhBuildSession(uh, level_request(cache));
  ASSERT_NE(second.Session.bits, 0u) << *second.Error;
  uh.uh_session_destroy(second.Session);
  EXPECT_GT(std::filesystem::file_size(cached[0]), 100u);  // packed again and saved over the damaged file
}

TEST(UnrealPluginContract, RemovesTheScenesObjectsTheLevelReplacesAndOverridesTheRate) {
  const FUhApi& uh = api();
  FUhSessionRequest request = level_request(cache_dir());
  request.SceneObjectsToRemove = TArray<FString>{"bunny"};
  request.HapticHz = 2000.0;  // the manager's override (0: the scene's 1000 Hz)
  FUhSessionBuild build = UhBuildSession(uh, request);
  ASSERT_NE(build.Session.bits, 0u) << *build.Error;
  EXPECT_EQ(build.Warnings.Num(), 1);  // the tool without a mesh only
  ASSERT_EQ(build.ObjectNames.Num(), 1);
  EXPECT_TRUE(build.ObjectNames[0] == FString("cube"));
  FUhHapticHookTable no_hooks;
  FString error;
  ASSERT_TRUE(UhStartSession(uh, build.Session, &UhDispatchTick, &no_hooks, error)) << *error;
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_EQ(uh.uh_session_stop(build.Session), UH_OK) << *uh.LastError();
  const char* report = nullptr;
  ASSERT_EQ(uh.uh_session_report_json(build.Session, &report), UH_OK);
  std::string text;  // the report without its indentation
  for (const char* c = report; *c != '\0'; ++c)
    if (*c != ' ' && *c != '\n') text += *c;
  // the haptic target rate (the collision one stays the scene's 1000 Hz)
  EXPECT_NE(text.find("\"target_hz\":2000"), std::string::npos) << text;
  uh.uh_session_destroy(build.Session);
}

TEST(UnrealPluginContract, AFailedBuildNamesTheCallAndTheFile) {
  FUhSessionRequest request;
  request.ScenePath = "/nonexistent/level-scene.json";
  const FUhSessionBuild build = UhBuildSession(api(), request);
  EXPECT_EQ(build.Session.bits, 0u);
  EXPECT_TRUE(build.Error.StartsWith("uh_scene_load")) << *build.Error;
  EXPECT_TRUE(build.Error.Contains("level-scene.json")) << *build.Error;
}

TEST(UnrealPluginContract, ConvertsTheTickStateAndContactEvents) {
  uh_state in{};
  in.time_s = 1.5;
  in.tool_position[1] = 0.25;
  in.tool_orientation[0] = 1.0;
  in.force[2] = 3.0;
  in.torque[0] = -1.0;
  in.contact_pairs = 7;
  in.haptic_ticks = 1500;
  in.buttons = 2;
  FUhTickState out;
  UhToTickState(in, out);
  EXPECT_EQ(out.TimeSeconds, 1.5);
  EXPECT_EQ(out.ToolPosition[1], 0.25);
  EXPECT_EQ(out.ToolOrientation[0], 1.0);
  EXPECT_EQ(out.Force[2], 3.0);
  EXPECT_EQ(out.Torque[0], -1.0);
  EXPECT_EQ(out.ContactPairs, 7);
  EXPECT_EQ(out.HapticTicks, 1500u);
  EXPECT_EQ(out.Buttons, 2u);

  uh_contact_event event{};
  event.kind = UH_CONTACT_END;
  event.object = 1;
  event.tool = 1;
  const TArray<FString> names{"bunny", "cube"};
  const FUhContact contact = UhToContact(event, names);
  EXPECT_TRUE(contact.ObjectName == FString("cube"));
  EXPECT_EQ(contact.Tool, 1);
  EXPECT_FALSE(contact.bBegin);
  event.object = 5;  // an index the session does not have
  EXPECT_TRUE(UhToContact(event, names).ObjectName.IsEmpty());
}

TEST(UnrealPluginContract, UnrealsFrameRoundTripsThroughLibuhs) {
  double metres[3];
  UhConvert::Position(FVector(100.0, 50.0, -20.0), metres);
  EXPECT_DOUBLE_EQ(metres[0], 1.0);
  EXPECT_DOUBLE_EQ(metres[1], -0.5);  // Unreal is left-handed: Y mirrored
  EXPECT_DOUBLE_EQ(metres[2], -0.2);
  const FVector back = UhConvert::ToUnrealPosition(metres);
  EXPECT_DOUBLE_EQ(back.Y, 50.0);
  double q[4];
  UhConvert::Orientation(FQuat(0.1, 0.2, 0.3, 0.9), q);
  const FQuat round = UhConvert::ToUnrealOrientation(q);
  EXPECT_DOUBLE_EQ(round.X, 0.1);
  EXPECT_DOUBLE_EQ(round.Y, 0.2);
  EXPECT_DOUBLE_EQ(round.Z, 0.3);
  EXPECT_DOUBLE_EQ(round.W, 0.9);
}
