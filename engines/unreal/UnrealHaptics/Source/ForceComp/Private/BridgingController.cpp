#include "BridgingController.h"

#include "HapticManager.h"

void ABridgingController::BeginPlay()
{
	Super::BeginPlay();
	if (HapticManager != nullptr)
	{
		HapticManager->OnMoveOnHapticTick.AddDynamic(this, &ABridgingController::Move);
	}
}

void ABridgingController::Move(FVector ToolPosition, FRotator ToolOrientation, int32 /*Buttons: the tool follows the pose only*/)
{
	if (ToolActor != nullptr)
	{
		ToolActor->SetActorLocationAndRotation(ToolPosition, ToolOrientation);
	}
}
