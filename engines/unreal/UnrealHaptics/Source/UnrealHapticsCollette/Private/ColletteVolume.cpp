#include "ColletteVolume.h"

#include "ColletteStaticMeshActor.h"
#include "HapticManager.h"
#include "UnrealHapticsLog.h"

AColletteVolume::AColletteVolume()
{
	PrimaryActorTick.bCanEverTick = true;
	PrimaryActorTick.TickGroup = TG_PostPhysics;  // after the manager polled this frame's events
}

// The manager, found on first use: AddCollisionWatcher may come from another actor's BeginPlay
// before this volume's own.
AHapticManager* AColletteVolume::Manager()
{
	if (AHapticManager::Resolve(HapticManager, *this, TEXT("no collision events")) != nullptr && !bBound)
	{
		HapticManager->OnNativeContact.AddUObject(this, &AColletteVolume::HandleContact);
		bBound = true;
	}
	return HapticManager;
}

void AColletteVolume::BeginPlay()
{
	Super::BeginPlay();
	if (Manager() == nullptr)
	{
		return;
	}
	for (AColletteStaticMeshActor* Object : WatchedObjects)
	{
		AddCollisionWatcher(Object, Tool);
	}
}

void AColletteVolume::EndPlay(const EEndPlayReason::Type Reason)
{
	if (HapticManager != nullptr)
	{
		HapticManager->OnNativeContact.RemoveAll(this);
	}
	bBound = false;
	Super::EndPlay(Reason);
}

void AColletteVolume::AddCollisionWatcher(AActor* A, AActor* B)
{
	AColletteStaticMeshActor* Object = Cast<AColletteStaticMeshActor>(A);
	if (Object == nullptr)
	{
		Object = Cast<AColletteStaticMeshActor>(B);
		B = A;
	}
	if (Object == nullptr)
	{
		UE_LOG(LogUnrealHaptics, Warning, TEXT("%s: AddCollisionWatcher(%s, %s): neither is a ColletteStaticMeshActor"), *GetName(),
			*GetNameSafe(A), *GetNameSafe(B));
		return;
	}
	if (Manager() == nullptr)
	{
		return;
	}
	if (B != nullptr)
	{
		Tool = B;
	}
	if (HapticManager->Watch(Object->ObjectName()))  // logs a call after the session's build began
	{
		Watched.AddUnique(Object);
	}
}

AColletteStaticMeshActor* AColletteVolume::WatchedNamed(const FString& ObjectName) const
{
	for (const TWeakObjectPtr<AColletteStaticMeshActor>& W : Watched)
	{
		if (W.IsValid() && W->ObjectName() == ObjectName)
		{
			return W.Get();
		}
	}
	return nullptr;
}

void AColletteVolume::HandleContact(const FUhContact& Contact)
{
	AColletteStaticMeshActor* Object = WatchedNamed(Contact.ObjectName);
	if (Object == nullptr)
	{
		return;
	}
	FUhCollisionData Data;
	Data.Event = Contact.bBegin ? EUhCollisionEvent::Begin : EUhCollisionEvent::End;
	Data.Pairs = Contact.Pairs;
	Data.Volume = Contact.Volume;
	Data.Force = HapticManager->GetNewestState().Force;
	if (Contact.bBegin)
	{
		Touching.Add(Contact.ObjectName, Data);
	}
	else
	{
		Touching.Remove(Contact.ObjectName);
	}
	OnCollision.Broadcast(Object, Tool, Data);
}

void AColletteVolume::Tick(float DeltaSeconds)
{
	Super::Tick(DeltaSeconds);
	if (HapticManager == nullptr || !HapticManager->IsRunning())
	{
		return;
	}
	const FUhHapticState State = HapticManager->GetNewestState();
	for (const TWeakObjectPtr<AColletteStaticMeshActor>& W : Watched)
	{
		if (FUhCollisionData* Data = W.IsValid() ? Touching.Find(W->ObjectName()) : nullptr)
		{
			Data->Event = EUhCollisionEvent::Contact;
			Data->Pairs = State.ContactPairs;
			Data->Force = State.Force;
			OnCollision.Broadcast(W.Get(), Tool, *Data);
		}
	}
}
