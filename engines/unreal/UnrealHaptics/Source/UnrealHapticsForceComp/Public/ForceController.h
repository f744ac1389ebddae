// AForceController (the paper's ForceController): hands its ForceComponent's settings to the
// HapticManager before play starts, and reports the force rendered: ForceOnHapticTick (Blueprint,
// game thread, once per frame with the newest state). The force itself is computed by libuh on its
// haptic thread; real-time code registers AHapticManager::AddHapticTickHook instead.
#pragma once

#include "CoreMinimal.h"
#include "GameFramework/Actor.h"

#include "ForceController.generated.h"

class AHapticManager;
class UForceComponent;

DECLARE_DYNAMIC_MULTICAST_DELEGATE_TwoParams(FUhForceRendered, FVector, Force, FVector, Torque);

UCLASS()
class UNREALHAPTICSFORCECOMP_API AForceController : public AActor
{
	GENERATED_BODY()

public:
	/** Unset: the level's first HapticManager. */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Haptics") TObjectPtr<AHapticManager> HapticManager;
	/** The tool actor, whose ForceComponent sets the tool (none: the scene's tool is kept). */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Haptics") TObjectPtr<AActor> ToolActor;

	UPROPERTY(BlueprintAssignable, Category = "Haptics") FUhForceRendered ForceOnHapticTick;

protected:
	virtual void BeginPlay() override;

private:
	UFUNCTION() void Forward(FVector Force, FVector Torque);
};
