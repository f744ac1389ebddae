// AUnrealHapticsDemo: drop it into any level and press Play to feel (and see) libuh's default
// scene through the paper's parts, with no asset of the plugin's own. It spawns, before the
// session is built:
//  - a HapticManager (unless the level has one) on libuh's default scene: a stylus on the
//    simulated "sim-raster" device sweeping a 10 cm Stanford bunny into deep contact;
//  - the bunny as a ColletteStaticMeshActor from the staged mesh file (replacing the scene's own,
//    drawn with debug lines), at the world origin where the simulated device sweeps;
//  - the stylus (the engine's sphere, 1 cm), moved by a BridgingController;
//  - a ForceController (the scene's tool and force law) and a ColletteVolume watching the bunny,
//    whose events and the force rendered are printed on screen.
// A real device: set the manager's scene file to one naming its driver.
#pragma once

#include "CoreMinimal.h"
#include "ColletteVolume.h"
#include "GameFramework/Actor.h"

#include "UnrealHapticsDemo.generated.h"

class AHapticManager;
class UStaticMesh;

UCLASS(meta = (DisplayName = "UnrealHaptics Demo"))
class UNREALHAPTICSDEMO_API AUnrealHapticsDemo : public AActor
{
	GENERATED_BODY()

public:
	AUnrealHapticsDemo();

	/** What stands for the stylus (default: the engine's sphere). */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Demo") TObjectPtr<UStaticMesh> StylusMesh;
	/** The stylus' scale (the engine's sphere is 1 m across). */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Demo", meta = (ClampMin = "0.001")) float StylusScale = 0.01f;
	/** Print the force and the collision events on screen. */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Demo") bool bPrintOnScreen = true;

protected:
	virtual void BeginPlay() override;

private:
	template <typename T>
	T* SpawnConfigured(const FTransform& Transform, TFunctionRef<void(T&)> Configure);
	void SpawnBunny(AHapticManager& Manager);
	void DrawMeshFile(const FString& Path, const FTransform& Transform, double MetersPerUnit) const;

	UFUNCTION() void PrintForce(FVector Force, FVector Torque);
	UFUNCTION() void PrintCollision(AActor* A, AActor* B, const FUhCollisionData& Data);

	UPROPERTY() TObjectPtr<AActor> Stylus;
	UPROPERTY() TObjectPtr<AActor> Bunny;
};
