// AColletteVolume (the paper's ColletteVolume): the objects the game wants collision events for.
// AddCollisionWatcher(A, B) (or WatchedObjects in the editor) watches a ColletteStaticMeshActor
// against the tool: libuh collides the tool with it even if its bWatch is off, and never stops
// colliding with objects the volume does not name. OnCollision fires on the game thread when a
// contact begins, every frame while it lasts (with the newest state) and when it ends.
#pragma once

#include "CoreMinimal.h"
#include "GameFramework/Actor.h"

#include "ColletteVolume.generated.h"

class AHapticManager;
class AColletteStaticMeshActor;
struct FUhContact;

UENUM(BlueprintType)
enum class EUhCollisionEvent : uint8 { Begin, Contact, End };

USTRUCT(BlueprintType)
struct UNREALHAPTICSCOLLETTE_API FUhCollisionData
{
	GENERATED_BODY()
	UPROPERTY(BlueprintReadOnly, Category = "Collette") EUhCollisionEvent Event = EUhCollisionEvent::Begin;
	/** Overlapping sphere pairs. */
	UPROPERTY(BlueprintReadOnly, Category = "Collette") int32 Pairs = 0;
	/** Overlap volume of the latest contact event [m^3]. */
	UPROPERTY(BlueprintReadOnly, Category = "Collette") double Volume = 0.0;
	/** The force sent to the device in the newest tick [N]. */
	UPROPERTY(BlueprintReadOnly, Category = "Collette") FVector Force = FVector::ZeroVector;
};

DECLARE_DYNAMIC_MULTICAST_DELEGATE_ThreeParams(FUhOnCollision, AActor*, A, AActor*, B, const FUhCollisionData&, Data);

UCLASS()
class UNREALHAPTICSCOLLETTE_API AColletteVolume : public AActor
{
	GENERATED_BODY()

public:
	AColletteVolume();

	/** Unset: the level's first HapticManager. */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Collette") TObjectPtr<AHapticManager> HapticManager;
	/** The tool's actor, passed as B in OnCollision. */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Collette") TObjectPtr<AActor> Tool;
	/** Objects watched against the tool from the start (as AddCollisionWatcher(Object, Tool)). */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Collette") TArray<TObjectPtr<AColletteStaticMeshActor>> WatchedObjects;

	/** Watches A (a ColletteStaticMeshActor) against B (the tool; may be null). In BeginPlay of any
	 *  actor (before the manager's first Tick); later calls are logged and ignored. */
	UFUNCTION(BlueprintCallable, Category = "Collette") void AddCollisionWatcher(AActor* A, AActor* B);

	UPROPERTY(BlueprintAssignable, Category = "Collette") FUhOnCollision OnCollision;

protected:
	virtual void BeginPlay() override;
	virtual void EndPlay(const EEndPlayReason::Type Reason) override;
	virtual void Tick(float DeltaSeconds) override;

private:
	AHapticManager* Manager();
	void HandleContact(const FUhContact& Contact);
	AColletteStaticMeshActor* WatchedNamed(const FString& ObjectName) const;

	TArray<TWeakObjectPtr<AColletteStaticMeshActor>> Watched;
	TMap<FString, FUhCollisionData> Touching;
	bool bBound = false;
};
