// AHapticManager (the paper's HapticManager): owns one libuh session (its haptic, collision and
// monitor threads). The scene is the scene file (or libuh's default scene) plus what the other
// actors register before play starts: ColletteStaticMeshActors (objects), a ForceComponent (the
// tool), ColletteVolumes (watched pairs). The session starts on the manager's first Tick, after
// every actor's BeginPlay, and EndPlay always stops it (zero force, every thread joined).
//
// Threads: MoveOnHapticTick / ForceOnHapticTick are native delegates broadcast on the haptic thread
// after every tick (1 kHz): real-time code only (no allocation, no locks, no UObject access), bound
// before play starts. OnMoveOnHapticTick / OnForceOnHapticTick are Blueprint events on the game
// thread, once per frame, with the newest state. Contact events reach ColletteVolumes on the game
// thread.
#pragma once

#include "CoreMinimal.h"
#include "GameFramework/Actor.h"
#include "uh/uh.h"

#include "HapticManager.generated.h"

/** The newest haptic state in Unreal's frame (centimetres; force in newtons). */
USTRUCT(BlueprintType)
struct HAPTICO_API FUhHapticState
{
	GENERATED_BODY()
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") double TimeSeconds = 0.0;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") FVector ToolPosition = FVector::ZeroVector;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") FRotator ToolOrientation = FRotator::ZeroRotator;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") FVector Force = FVector::ZeroVector;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") FVector Torque = FVector::ZeroVector;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") int32 ContactPairs = 0;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") int64 HapticTicks = 0;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") int64 MissedDeadlines = 0;
	UPROPERTY(BlueprintReadOnly, Category = "Haptics") int32 Buttons = 0;  // bit i: button i
};

/** A static object as registered by a ColletteStaticMeshActor, already in libuh's frame (metres). */
struct HAPTICO_API FUhObjectSpec
{
	FString Name;
	TArray<double> Vertices;  // x, y, z per vertex [m]
	TArray<int32> Indices;    // three per triangle
	FString IstPath;          // or a prebuilt .ist (then no arrays)
	double Position[3] = {0, 0, 0};
	double Orientation[4] = {1, 0, 0, 0};
	int64 Spheres = 10000;
	bool bWatch = true;
	TWeakObjectPtr<AActor> Actor;
};

/** The tool as a ForceComponent registers it; without a mesh the scene's own tool is kept. */
struct HAPTICO_API FUhToolSpec
{
	FString MeshPath;         // a mesh or .ist file; empty: keep the scene's tool
	double MetersPerUnit = 1.0;
	int64 Spheres = 10000;
	bool bThreeDof = false;
	bool bPaperLaw = false;   // the force law: gradient (false) or the paper's eq. 1
	double Stiffness = 2.0e4, ForceScale = 1.0e7, Damping = 2.0, MassKg = 0.05, MaxForceN = 8.0, MaxTorqueNm = 0.3;
	FString DeviceDriver;     // empty: "sim-raster" (the default scene's)
	FString DeviceConfigJson;
};

DECLARE_MULTICAST_DELEGATE_OneParam(FUhNativeTick, const uh_state&);
DECLARE_MULTICAST_DELEGATE_OneParam(FUhNativeContact, const uh_contact_event&);
DECLARE_DYNAMIC_MULTICAST_DELEGATE_ThreeParams(FUhMoveOnHapticTick, FVector, ToolPosition, FRotator, ToolOrientation, int32, Buttons);
DECLARE_DYNAMIC_MULTICAST_DELEGATE_TwoParams(FUhForceOnHapticTick, FVector, Force, FVector, Torque);

UCLASS()
class HAPTICO_API AHapticManager : public AActor
{
	GENERATED_BODY()

public:
	AHapticManager();

	/** The level's HapticManager (the first one), for actors whose HapticManager property is unset. */
	static AHapticManager* FindIn(UWorld* World);

	/** A scene file (docs/scenes.md); empty: libuh's default scene (the bunny, a simulated stylus). */
	UPROPERTY(EditAnywhere, Category = "Haptics") FFilePath SceneFile;
	/** Objects of the scene file that the level's ColletteStaticMeshActors replace (removed after
	 *  those are added); the default scene's object is "bunny". */
	UPROPERTY(EditAnywhere, Category = "Haptics") TArray<FString> SceneObjectsToRemove = {TEXT("bunny")};
	/** Rates [Hz]; 0 (haptic) or < 0 (collision): the scene's. */
	UPROPERTY(EditAnywhere, Category = "Haptics") double HapticHz = 0.0;
	UPROPERTY(EditAnywhere, Category = "Haptics") double CollisionHz = -1.0;
	UPROPERTY(EditAnywhere, Category = "Haptics") bool bRaisePriority = false;

	/** Haptic thread, every tick: real-time code only; bind before play starts. */
	FUhNativeTick MoveOnHapticTick;
	FUhNativeTick ForceOnHapticTick;
	/** Game thread, every contact begin/end of a watched object. */
	FUhNativeContact OnContact;

	/** Game thread, once per frame with the newest state. */
	UPROPERTY(BlueprintAssignable, Category = "Haptics") FUhMoveOnHapticTick OnMoveOnHapticTick;
	UPROPERTY(BlueprintAssignable, Category = "Haptics") FUhForceOnHapticTick OnForceOnHapticTick;

	UFUNCTION(BlueprintCallable, Category = "Haptics") FUhHapticState GetNewestState() const { return Newest; }
	UFUNCTION(BlueprintCallable, Category = "Haptics") bool IsRunning() const { return Session != nullptr && bStarted; }
	/** Stops the session (zero force, threads joined) and returns its report (JSON); idempotent. */
	UFUNCTION(BlueprintCallable, Category = "Haptics") FString StopHaptics();

	void RegisterObject(FUhObjectSpec Spec);
	void RegisterTool(const FUhToolSpec& Spec) { Tool = Spec; bHasTool = true; }
	void Watch(const FString& ObjectName) { Watched.AddUnique(ObjectName); }
	/** The object's index in the running session, or INDEX_NONE. */
	int32 ObjectIndex(const FString& Name) const;
	/** Moves a registered object while the session runs (Unreal's frame). */
	void SetObjectPose(const FString& Name, const FTransform& Transform);

protected:
	virtual void Tick(float DeltaSeconds) override;
	virtual void EndPlay(const EEndPlayReason::Type Reason) override;

private:
	bool StartSession();
	void CloseSession();
	static void OnHapticTick(void* User, const uh_state* State);

	TArray<FUhObjectSpec> Objects;
	FUhToolSpec Tool;
	bool bHasTool = false;
	TArray<FString> Watched;
	TArray<FString> SessionObjectNames;
	uh_session* Session = nullptr;
	bool bStarted = false;
	bool bTried = false;
	FUhHapticState Newest;
	FString Report;
};
