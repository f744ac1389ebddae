// AColletteStaticMeshActor (the paper's ColletteStaticMeshActor): a static mesh actor whose mesh
// (LOD 0 render data, through the actor's scale; the mesh needs "Allow CPU Access" in cooked
// builds) or a prebuilt .ist becomes a libuh collision object. It registers with the HapticManager
// in BeginPlay; while the session runs, its pose follows the actor (bFollowActor).
#pragma once

#include "CoreMinimal.h"
#include "Engine/StaticMeshActor.h"

#include "ColletteStaticMeshActor.generated.h"

class AHapticManager;

UCLASS()
class COLLETTE_API AColletteStaticMeshActor : public AStaticMeshActor
{
	GENERATED_BODY()

public:
	AColletteStaticMeshActor();

	UPROPERTY(EditAnywhere, Category = "Collette") TObjectPtr<AHapticManager> HapticManager;
	/** A prebuilt .ist file instead of the static mesh. */
	UPROPERTY(EditAnywhere, Category = "Collette") FFilePath IstFile;
	/** Leaf spheres when packing the mesh. */
	UPROPERTY(EditAnywhere, Category = "Collette") int64 Spheres = 10000;
	/** Watched against the tool even without a ColletteVolume naming it. */
	UPROPERTY(EditAnywhere, Category = "Collette") bool bWatch = true;
	/** Send the actor's pose while the session runs (the object moves in the haptic scene). */
	UPROPERTY(EditAnywhere, Category = "Collette") bool bFollowActor = true;

	/** The object's name in libuh: the actor's name. */
	FString ObjectName() const { return GetName(); }

protected:
	virtual void BeginPlay() override;
	virtual void Tick(float DeltaSeconds) override;

private:
	FTransform SentTransform;
};
