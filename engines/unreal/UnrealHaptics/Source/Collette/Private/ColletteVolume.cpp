#include "ColletteVolume.h"

#include "ColletteStaticMeshActor.h"
#include "HapticManager.h"

AColletteVolume::AColletteVolume()
{
	PrimaryActorTick.bCanEverTick = true;
	PrimaryActorTick.TickGroup = TG_PostPhysics;  // after the manager polled this frame's events
}

void AColletteVolume::BeginPlay()
{
	Super::BeginPlay();
	if (HapticManager == nullptr)
	{
		HapticManager = AHapticManager::FindIn(GetWorld());
	}
	if (HapticManager != nullptr)
	{
		HapticManager->OnContact.AddUObject(this, &AColletteVolume::HandleContact);
	}
}

void AColletteVolume::AddCollisionWatcher(AActor* A, AActor* B)
{
	AColletteStaticMeshActor* Object = Cast<AColletteStaticMeshActor>(A);
	if (Object == nullptr)
	{
		Object = Cast<AColletteStaticMeshActor>(B);
		B = A;
	}
	if (Object == nullptr || HapticManager == nullptr)
	{
		return;
	}
	if (B != nullptr)
	{
		Tool = B;
	}
	Watched.AddUnique(Object);
	HapticManager->Watch(Object->ObjectName());
}

AColletteStaticMeshActor* AColletteVolume::WatchedAt(int32 SessionIndex) const
{
	for (const TWeakObjectPtr<AColletteStaticMeshActor>& W : Watched)
	{
		if (W.IsValid() && HapticManager->ObjectIndex(W->ObjectName()) == SessionIndex)
		{
			return W.Get();
		}
	}
	return nullptr;
}

void AColletteVolume::HandleContact(const uh_contact_event& Event)
{
	AColletteStaticMeshActor* Object = WatchedAt(Event.object);
	if (Object == nullptr)
	{
		return;
	}
	FUhCollisionData Data;
	Data.Event = Event.kind == UH_CONTACT_BEGIN ? EUhCollisionEvent::Begin : EUhCollisionEvent::End;
	Data.Pairs = Event.pairs;
	Data.Volume = Event.volume;
	Data.Force = HapticManager->GetNewestState().Force;
	if (Data.Event == EUhCollisionEvent::Begin)
	{
		Touching.Add(Object->ObjectName(), Data);
	}
	else
	{
		Touching.Remove(Object->ObjectName());
	}
	OnCollision.Broadcast(Object, Tool, Data);
}

void AColletteVolume::Tick(float DeltaSeconds)
{
	Super::Tick(DeltaSeconds);
	if (HapticManager == nullptr)
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
