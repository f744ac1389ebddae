// ABridgingController (the paper's BridgingController): bridges the device into the level. The
// tool actor follows the device on the game thread, once per frame, at the newest state's pose
// (AHapticManager::OnMoveOnHapticTick).
#pragma once

#include "CoreMinimal.h"
#include "GameFramework/Actor.h"

#include "BridgingController.generated.h"

class AHapticManager;

UCLASS()
class UNREALHAPTICSFORCECOMP_API ABridgingController : public AActor
{
	GENERATED_BODY()

public:
	/** Unset: the level's first HapticManager. */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Haptics") TObjectPtr<AHapticManager> HapticManager;
	/** The actor that follows the device (the stylus). */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Haptics") TObjectPtr<AActor> ToolActor;

protected:
	virtual void BeginPlay() override;

private:
	UFUNCTION() void Move(FVector ToolPosition, FRotator ToolOrientation, int32 Buttons);
};
