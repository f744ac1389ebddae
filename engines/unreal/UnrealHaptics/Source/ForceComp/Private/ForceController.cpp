#include "ForceController.h"

#include "ForceComponent.h"
#include "HapticManager.h"

void AForceController::BeginPlay()
{
	Super::BeginPlay();
	if (HapticManager == nullptr)
	{
		return;
	}
	if (const UForceComponent* Component = ToolActor != nullptr ? ToolActor->FindComponentByClass<UForceComponent>() : nullptr)
	{
		HapticManager->RegisterTool(Component->ToolSpec());
	}
	HapticManager->OnForceOnHapticTick.AddDynamic(this, &AForceController::Forward);
}

void AForceController::Forward(FVector Force, FVector Torque)
{
	ForceOnHapticTick.Broadcast(Force, Torque);
}
