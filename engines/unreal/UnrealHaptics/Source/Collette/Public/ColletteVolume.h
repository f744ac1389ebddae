// AColletteVolume (the paper's ColletteVolume): the pairs the game wants collision events for.
// AddCollisionWatcher(A, B) watches a ColletteStaticMeshActor against the tool (libuh computes
// contacts between the tool and watched objects); OnCollision fires on the game thread when a
// contact begins, every frame while it lasts (with the newest state) and when it ends.
#pragma once

#include "CoreMinimal.h"
#include "GameFramework/Actor.h"
#include "uh/uh.h"

#include "ColletteVolume.generated.h"

class AHapticManager;
class AColletteStaticMeshActor;

UENUM(BlueprintType)
enum class EUhCollisionEvent : uint8 { Begin, Contact, End };

USTRUCT(BlueprintType)
struct COLLETTE_API FUhCollisionData
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
class COLLETTE_API AColletteVolume : public AActor
{
	GENERATED_BODY()

public:
	AColletteVolume();

	UPROPERTY(EditAnywhere, Category = "Collette") TObjectPtr<AHapticManager> HapticManager;
	/** The tool's actor, passed as B in OnCollision. */
	UPROPERTY(EditAnywhere, Category = "Collette") TObjectPtr<AActor> Tool;

	/** Watches A (a ColletteStaticMeshActor) against B (the tool; may be null). Before play starts. */
	UFUNCTION(BlueprintCallable, Category = "Collette") void AddCollisionWatcher(AActor* A, AActor* B);

	UPROPERTY(BlueprintAssignable, Category = "Collette") FUhOnCollision OnCollision;

protected:
	virtual void BeginPlay() override;
	virtual void Tick(float DeltaSeconds) override;

private:
	void HandleContact(const uh_contact_event& Event);
	AColletteStaticMeshActor* WatchedAt(int32 SessionIndex) const;

	TArray<TWeakObjectPtr<AColletteStaticMeshActor>> Watched;
	TMap<FString, FUhCollisionData> Touching;
};
