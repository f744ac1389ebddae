#include "BridgingController.h"

#include "HapticManager.h"
#include "UnrealHapticsLog.h"

void ABridgingController::BeginPlay()
{
	Super::BeginPlay();
	if (AHapticManager::Resolve(HapticManager, *this, TEXT("nothing moves with the device")) == nullptr)
	{
		return;
	}
	if (ToolActor == nullptr)
	{
		UE_LOG(LogUnrealHaptics, Error, TEXT("%s: no ToolActor set: nothing moves with the device"), *GetName());
		return;
	}
	HapticManager->OnMoveOnHapticTick.AddDynamic(this, &ABridgingController::Move);
}

void ABridgingController::Move(FVector ToolPosition, FRotator ToolOrientation, int32 /*Buttons: the tool follows the pose only*/)
{
	if (ToolActor != nullptr)
	{
		ToolActor->SetActorLocationAndRotation(ToolPosition, ToolOrientation);
	}
}
