// The parts the other actors hand to the HapticManager before play starts, and the state the
// native haptic-tick hooks receive. Plain data in libuh's frame (metres, right-handed; UhConvert
// converts): no libuh type appears here, so uh.h stays private to this module.
#pragma once

#include "CoreMinimal.h"

/** A static object as a ColletteStaticMeshActor registers it. Its shape: exactly one of the
 *  arrays (a static mesh's triangles), IstPath (a prebuilt .ist) or MeshPath (a closed mesh file
 *  libuh packs). Paths are absolute (UhPaths::ResolveProjectFile). */
struct FUhObjectSpec
{
	FString Name;
	TArray<double> Vertices;  // x, y, z per vertex [m]
	TArray<int32> Indices;    // three per triangle
	FString IstPath;
	FString MeshPath;
	double MeshMetersPerUnit = 1.0;  // MeshPath's length unit [m]
	double Position[3] = {0, 0, 0};
	double Orientation[4] = {1, 0, 0, 0};  // (w, x, y, z)
	int64 Spheres = 10000;
	bool bWatch = true;  // false: the tool passes through it (libuh queries only watched pairs)
};

/** The tool as a ForceComponent registers it; without a mesh the scene's own tool is kept. */
struct FUhToolSpec
{
	FString MeshPath;  // a mesh or .ist file (absolute); empty: keep the scene's tool
	double MetersPerUnit = 1.0;
	int64 Spheres = 10000;
	bool bThreeDof = false;
	bool bPaperLaw = false;  // the force law: gradient (false) or the paper's eq. 1
	double Stiffness = 2.0e4, ForceScale = 1.0e7, Damping = 2.0, MassKg = 0.05, MaxForceN = 8.0, MaxTorqueNm = 0.3;
	FString DeviceDriver;  // empty: "sim-raster" (the default scene's)
	FString DeviceConfigJson;
};

/** One haptic tick as the native hooks see it, in libuh's frame (metres, newtons). */
struct FUhTickState
{
	double TimeSeconds = 0.0;
	double ToolPosition[3] = {0, 0, 0};
	double ToolOrientation[4] = {1, 0, 0, 0};
	double Force[3] = {0, 0, 0};
	double Torque[3] = {0, 0, 0};
	int32 ContactPairs = 0;
	uint64 HapticTicks = 0;
	uint32 Buttons = 0;
};

/** A native per-tick hook: called on libuh's haptic thread after every tick (1 kHz or more).
 *  Real-time code only: no allocation, no locks, no logging, no UObject access. */
using FUhHapticHookFn = void (*)(void* User, const FUhTickState& State);

/** The hooks the haptic thread calls: a fixed array, filled on the game thread before the session
 *  starts and read-only while it runs (the thread's start orders the writes before its reads). */
struct FUhHapticHookTable
{
	static constexpr int32 Capacity = 8;
	FUhHapticHookFn Fns[Capacity] = {};
	void* Users[Capacity] = {};
	int32 Count = 0;
};

/** A contact of the tool with a watched object began or ended (game thread, from the event queue). */
struct FUhContact
{
	FString ObjectName;
	int32 Tool = 0;  // the tool's index in the scene
	bool bBegin = true;
	double TimeSeconds = 0.0;
	double Volume = 0.0;  // overlap volume [m^3] (0 at the end)
	int32 Pairs = 0;
};
