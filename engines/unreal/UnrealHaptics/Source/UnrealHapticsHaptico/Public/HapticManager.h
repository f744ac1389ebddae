// AHapticManager (the paper's HapticManager): owns one libuh session (its haptic, collision and
// monitor threads). The scene is the scene file (or libuh's default scene) plus what the other
// actors register in their BeginPlay: ColletteStaticMeshActors (objects), a ForceComponent (the
// tool), ColletteVolumes (watched objects). On the manager's first Tick (after every BeginPlay of
// the level) the registrations close and the session is built on a worker thread (meshes packed,
// cached in the project's Saved/UnrealHaptics); it starts on the game thread when that is done.
// EndPlay (and BeginDestroy, should EndPlay never come) stops it: zero force, every thread joined.
//
// Threads:
//  - native haptic-tick hooks (AddHapticTickHook): plain function pointers in a fixed array, called
//    on libuh's haptic thread after every tick; registered on the game thread before the build
//    starts, refused (with a log) after. Real-time code only.
//  - everything a Blueprint sees (the state, OnMoveOnHapticTick, OnForceOnHapticTick, the session
//    and contact events) is made on the game thread, once per frame, from the polled newest state
//    and libuh's event queue.
#pragma once

#include "CoreMinimal.h"
#include "Async/Future.h"
#include "GameFramework/Actor.h"
#include "UhTypes.h"

#include "HapticManager.generated.h"

struct FUhSessionBuild;

/** The newest haptic state in Unreal's frame (centimetres; force in newtons). */
USTRUCT(BlueprintType)
struct UNREALHAPTICSHAPTICO_API FUhHapticState
{
	GENERATED_BODY()
	UPROPERTY(BlueprintReadOnly, Category = "Haptics", meta = (Units = "s")) double TimeSeconds = 0.0;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") FVector ToolPosition = FVector::ZeroVector;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") FRotator ToolOrientation = FRotator::ZeroRotator;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") FVector Force = FVector::ZeroVector;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") FVector Torque = FVector::ZeroVector;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") int32 ContactPairs = 0;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") int64 HapticTicks = 0;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") int64 MissedDeadlines = 0;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") int32 Buttons = 0;  // bit i: button i
};

/** A contact of the tool with a watched object, for Blueprints (game thread). */
USTRUCT(BlueprintType)
struct UNREALHAPTICSHAPTICO_API FUhContactEvent
{
	GENERATED_BODY()
	/** The object's name in libuh (a ColletteStaticMeshActor's actor name, or a scene file's object). */
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") FString ObjectName;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") bool bBegin = true;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") int32 Pairs = 0;
	/** Overlap volume [m^3] (0 at the end). */
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") double Volume = 0.0;
};

UENUM(BlueprintType)
enum class EUhSessionState : uint8
{
	Idle,      // registrations open (before the first Tick)
	Building,  // the scene is built and meshes are packed on a worker thread
	Running,
	Stopped,
	Failed
};

DECLARE_MULTICAST_DELEGATE_OneParam(FUhNativeContact, const FUhContact&);
DECLARE_DYNAMIC_MULTICAST_DELEGATE_ThreeParams(FUhMoveOnHapticTick, FVector, ToolPosition, FRotator, ToolOrientation, int32, Buttons);
DECLARE_DYNAMIC_MULTICAST_DELEGATE_TwoParams(FUhForceOnHapticTick, FVector, Force, FVector, Torque);
DECLARE_DYNAMIC_MULTICAST_DELEGATE(FUhSessionStarted);
DECLARE_DYNAMIC_MULTICAST_DELEGATE_OneParam(FUhSessionStopped, const FString&, ReportJson);
DECLARE_DYNAMIC_MULTICAST_DELEGATE_OneParam(FUhSessionFailed, const FString&, Message);
DECLARE_DYNAMIC_MULTICAST_DELEGATE_OneParam(FUhContactDelegate, const FUhContactEvent&, Contact);

UCLASS(meta = (PrioritizeCategories = "Haptics"))
class UNREALHAPTICSHAPTICO_API AHapticManager : public AActor
{
	GENERATED_BODY()

public:
	/** Whether some manager builds its session (packing); the editor module shows a notification. */
	static FSimpleMulticastDelegate OnPackingStarted;
	static FSimpleMulticastDelegate OnPackingFinished;

	AHapticManager();

	/** The level's HapticManager (the first one), for actors whose HapticManager property is unset. */
	static AHapticManager* FindIn(UWorld* World);
	/** An actor's HapticManager property, set to FindIn when unset; null (logged, with what the
	 *  actor then cannot do) when the level has none. */
	static AHapticManager* Resolve(TObjectPtr<AHapticManager>& Property, const AActor& Requester, const TCHAR* Consequence);

	/** A scene file (docs/scenes.md), relative to the project folder; empty: libuh's default scene
	 *  (the bunny, a stylus on a simulated device). */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Haptics", meta = (FilePathFilter = "Scene (*.json)|*.json", RelativeToGameDir))
	FFilePath SceneFile;
	/** Objects of the scene file that the level's ColletteStaticMeshActors replace (removed after
	 *  those are added; a name the file lacks is logged and ignored). The default scene's object is "bunny". */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Haptics") TArray<FString> SceneObjectsToRemove;
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Haptics", meta = (InlineEditConditionToggle)) bool bOverrideHapticRate = false;
	/** Haptic rate; unchecked: the scene's (1 kHz in the default scene). */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Haptics", meta = (EditCondition = "bOverrideHapticRate", ClampMin = "1", ClampMax = "10000", Units = "Hz"))
	double HapticHz = 1000.0;
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Haptics", meta = (InlineEditConditionToggle)) bool bOverrideCollisionRate = false;
	/** Collision rate (0: free-running); unchecked: the scene's. */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Haptics", meta = (EditCondition = "bOverrideCollisionRate", ClampMin = "0", ClampMax = "10000", Units = "Hz"))
	double CollisionHz = 1000.0;
	/** Ask for real-time scheduling of libuh's threads (Linux: SCHED_FIFO, needs the right to). */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Haptics", AdvancedDisplay) bool bRaisePriority = false;
	/** Draw the tool, the force and the contact pairs each frame (development builds). */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Haptics|Debug") bool bDrawDebug = false;
	/** Length of the drawn force arrow per newton. */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Haptics|Debug", meta = (EditCondition = "bDrawDebug", ClampMin = "0", Units = "cm"))
	float DebugCentimetersPerNewton = 2.0f;

	/** Game thread, once per frame with the newest state. */
	UPROPERTY(BlueprintAssignable, Category = "Haptics") FUhMoveOnHapticTick OnMoveOnHapticTick;
	UPROPERTY(BlueprintAssignable, Category = "Haptics") FUhForceOnHapticTick OnForceOnHapticTick;
	/** Game thread: the session runs (meshes packed, threads started). */
	UPROPERTY(BlueprintAssignable, Category = "Haptics") FUhSessionStarted OnSessionStarted;
	/** Game thread: the session stopped (StopHaptics, EndPlay); the report as JSON. */
	UPROPERTY(BlueprintAssignable, Category = "Haptics") FUhSessionStopped OnSessionStopped;
	/** Game thread: the session could not be made or started, or ended by itself (a device fault, a
	 *  libuh thread that ended: stopped first, OnSessionStopped); libuh's message. */
	UPROPERTY(BlueprintAssignable, Category = "Haptics") FUhSessionFailed OnSessionFailed;
	/** Game thread: a contact with a watched object began or ended. */
	UPROPERTY(BlueprintAssignable, Category = "Haptics") FUhContactDelegate OnContact;
	/** Game thread: the same contacts for native code (ColletteVolume). */
	FUhNativeContact OnNativeContact;

	UFUNCTION(BlueprintPure, Category = "Haptics") FUhHapticState GetNewestState() const { return Newest; }
	UFUNCTION(BlueprintPure, Category = "Haptics") EUhSessionState GetSessionState() const { return State; }
	UFUNCTION(BlueprintPure, Category = "Haptics") bool IsRunning() const { return State == EUhSessionState::Running; }
	/** The last failure's message (libuh's), empty if none. */
	UFUNCTION(BlueprintPure, Category = "Haptics") FString GetLastError() const { return LastError; }
	/** Stops the session (zero force, threads joined) and returns its report (JSON); idempotent. */
	UFUNCTION(BlueprintCallable, Category = "Haptics") FString StopHaptics();

	/** Game thread, before the session is built: a function called on the haptic thread after every
	 *  tick (at most FUhHapticHookTable::Capacity). False (logged) when called later, off the game
	 *  thread or when the array is full. */
	bool AddHapticTickHook(FUhHapticHookFn Fn, void* User);

	/** Game thread, in BeginPlay: the level's parts. False (logged) once the session is being built. */
	bool RegisterObject(FUhObjectSpec Spec);
	bool RegisterTool(const FUhToolSpec& Spec);
	bool Watch(const FString& ObjectName);
	/** The object's index in the running session, or INDEX_NONE. */
	int32 ObjectIndex(const FString& Name) const;
	/** Moves a registered object while the session runs (Unreal's frame). */
	void SetObjectPose(const FString& Name, const FTransform& Transform);

protected:
	virtual void Tick(float DeltaSeconds) override;
	virtual void EndPlay(const EEndPlayReason::Type Reason) override;
	virtual void BeginDestroy() override;

private:
	bool AcceptsRegistration(const TCHAR* What, const FString& Name) const;
	void BeginBuild();
	void FinishBuild(FUhSessionBuild& Build);
	void Fail(const FString& Message);
	void DiscardPendingBuild();
	void PollState();
	void PollEvents();
	void StopIfEndedByItself();
	void DrawDebug() const;
	void CloseSession();

	TArray<FUhObjectSpec> Objects;
	FUhToolSpec Tool;
	bool bHasTool = false;
	TArray<FString> Watched;
	FUhHapticHookTable HookTable;
	TArray<FString> SessionObjectNames;
	TFuture<TSharedPtr<FUhSessionBuild>> PendingBuild;  // shared: FUhSessionBuild is private to this module
	uint64 SessionId = 0;  // libuh's uh_session_id (its bits); 0: none
	EUhSessionState State = EUhSessionState::Idle;
	FUhHapticState Newest;
	FString Report;
	FString LastError;
};
