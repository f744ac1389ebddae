// The C API call sequence behind AHapticManager's session: the scene built from what the level
// registered, the session opened (every tree loaded or packed), then started with the tick hook.
// Free of UObjects so that the slow part runs on a worker thread (packing takes seconds), and so
// that the repository's test command compiles and runs it against the real libuh with minimal
// stand-ins for the UE types it touches (engines/unreal/tests): a renamed libuh function or field
// breaks that test, not an Unreal user's build.
#pragma once

#include "CoreMinimal.h"
#include "UhTypes.h"
#include "uh/uh.h"

struct FUhApi;

/** Everything a session is made of, gathered on the game thread before the build starts. */
struct FUhSessionRequest
{
	FString ScenePath;  // absolute; empty: libuh's default scene (the bunny, a simulated stylus)
	TArray<FUhObjectSpec> Objects;
	TArray<FString> SceneObjectsToRemove;  // the scene file's objects the level replaces
	TArray<FString> Watched;  // objects a ColletteVolume watches: watched even when their bWatch is off
	bool bHasTool = false;
	FUhToolSpec Tool;
	double HapticHz = 0.0;      // 0: the scene's rate
	double CollisionHz = -1.0;  // < 0: the scene's rate (0: free-running)
	bool bRaisePriority = false;
	FString CacheDir;  // packed meshes: libuh's cache of mesh files, the plugin's of static meshes
};

/** What the build made. */
struct FUhSessionBuild
{
	uh_session_id Session{};       // opened, not started; zero on failure
	FString Error;                  // the failing call and libuh's message
	TArray<FString> Warnings;       // worth a log line, not a failure
	TArray<FString> ObjectNames;    // the session's objects by index
};

/** Builds the scene and opens the session. Any thread; takes seconds when meshes are packed. */
FUhSessionBuild UhBuildSession(const FUhApi& Api, const FUhSessionRequest& Request);

/** Binds the tick function and starts the threads; on failure returns libuh's message. */
bool UhStartSession(const FUhApi& Api, uh_session_id Session, uh_tick_fn Fn, void* User, FString& OutError);

/** libuh's state as the hooks see it (haptic thread: copies only). */
void UhToTickState(const uh_state& In, FUhTickState& Out);

/** The tick function the session is started with: `User` is an FUhHapticHookTable; calls each hook
 *  with the converted state (haptic thread, real-time: no allocation, no locks). */
void UhDispatchTick(void* User, const uh_state* State);

/** A contact event with its object's name (game thread). */
FUhContact UhToContact(const uh_contact_event& In, const TArray<FString>& ObjectNames);
