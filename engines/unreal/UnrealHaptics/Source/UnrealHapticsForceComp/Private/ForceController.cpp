#include "ForceController.h"

#include "ForceComponent.h"
#include "HapticManager.h"
#include "UhTypes.h"
#include "UnrealHapticsLog.h"

void AForceController::BeginPlay()
{
	Super::BeginPlay();
	if (AHapticManager::Resolve(HapticManager, *this, TEXT("no tool registered, no force reported")) == nullptr)
	{
		return;
	}
	if (const UForceComponent* Component = ToolActor != nullptr ? ToolActor->FindComponentByClass<UForceComponent>() : nullptr)
	{
		HapticManager->RegisterTool(Component->ToolSpec());  // logs a call after the session's build began
	}
	else
	{
		UE_LOG(LogUnrealHaptics, Log, TEXT("%s: no ForceComponent on the ToolActor: the scene's tool and force are kept"), *GetName());
	}
	HapticManager->OnForceOnHapticTick.AddDynamic(this, &AForceController::Forward);
}

void AForceController::Forward(FVector Force, FVector Torque)
{
	ForceOnHapticTick.Broadcast(Force, Torque);
}
