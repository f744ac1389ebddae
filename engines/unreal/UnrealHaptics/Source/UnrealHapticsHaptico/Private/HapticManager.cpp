#include "HapticManager.h"

#include "Async/Async.h"
#include "DrawDebugHelpers.h"
#include "EngineUtils.h"
#include "HAL/FileManager.h"
#include "Misc/Paths.h"
#include "UhApi.h"
#include "UhConvert.h"
#include "UhPaths.h"
#include "UhSessionBuilder.h"
#include "UnrealHapticsLog.h"

namespace
{
	// the session's id as libuh takes it (the header keeps its bits: uh.h is private to this module)
	uh_session_id AsId(uint64 Bits)
	{
		return uh_session_id{Bits};
	}
}

FSimpleMulticastDelegate AHapticManager::OnPackingStarted;
FSimpleMulticastDelegate AHapticManager::OnPackingFinished;

AHapticManager::AHapticManager()
{
	PrimaryActorTick.bCanEverTick = true;
	PrimaryActorTick.TickGroup = TG_PrePhysics;
	PrimaryActorTick.bTickEvenWhenPaused = true;  // libuh's threads run on while the game is paused
}

AHapticManager* AHapticManager::FindIn(UWorld* World)
{
	if (World == nullptr)
	{
		return nullptr;
	}
	TActorIterator<AHapticManager> It(World);
	return It ? *It : nullptr;
}

AHapticManager* AHapticManager::Resolve(TObjectPtr<AHapticManager>& Property, const AActor& Requester, const TCHAR* Consequence)
{
	if (Property == nullptr)
	{
		Property = FindIn(Requester.GetWorld());
	}
	if (Property == nullptr)
	{
		UE_LOG(LogUnrealHaptics, Error, TEXT("%s: no HapticManager in the level: %s"), *Requester.GetName(), Consequence);
	}
	return Property;
}

bool AHapticManager::AcceptsRegistration(const TCHAR* What, const FString& Name) const
{
	if (!IsInGameThread())
	{
		UE_LOG(LogUnrealHaptics, Error, TEXT("%s: %s '%s' off the game thread: refused"), *GetName(), What, *Name);
		return false;
	}
	if (State != EUhSessionState::Idle)
	{
		UE_LOG(LogUnrealHaptics, Warning, TEXT("%s: %s '%s' after the session's build began: ignored (register in BeginPlay, before the manager's first Tick)"),
			*GetName(), What, *Name);
		return false;
	}
	return true;
}

bool AHapticManager::AddHapticTickHook(FUhHapticHookFn Fn, void* User)
{
	if (Fn == nullptr || !AcceptsRegistration(TEXT("AddHapticTickHook"), FString()))
	{
		return false;
	}
	if (HookTable.Count == FUhHapticHookTable::Capacity)
	{
		UE_LOG(LogUnrealHaptics, Error, TEXT("%s: more than %d haptic tick hooks: refused"), *GetName(), FUhHapticHookTable::Capacity);
		return false;
	}
	HookTable.Fns[HookTable.Count] = Fn;
	HookTable.Users[HookTable.Count] = User;
	++HookTable.Count;
	return true;
}

bool AHapticManager::RegisterObject(FUhObjectSpec Spec)
{
	if (!AcceptsRegistration(TEXT("RegisterObject"), Spec.Name))
	{
		return false;
	}
	Objects.Add(MoveTemp(Spec));
	return true;
}

bool AHapticManager::RegisterTool(const FUhToolSpec& Spec)
{
	if (!AcceptsRegistration(TEXT("RegisterTool"), Spec.MeshPath))
	{
		return false;
	}
	Tool = Spec;
	bHasTool = true;
	return true;
}

bool AHapticManager::Watch(const FString& ObjectName)
{
	if (!AcceptsRegistration(TEXT("Watch"), ObjectName))
	{
		return false;
	}
	Watched.AddUnique(ObjectName);
	return true;
}

int32 AHapticManager::ObjectIndex(const FString& Name) const
{
	return SessionObjectNames.IndexOfByKey(Name);
}

void AHapticManager::SetObjectPose(const FString& Name, const FTransform& Transform)
{
	const FUhApi* Api = FUhApi::Get();
	const int32 Index = ObjectIndex(Name);
	if (Api == nullptr || !IsRunning() || Index == INDEX_NONE)
	{
		return;
	}
	double P[3], Q[4];
	UhConvert::Position(Transform.GetLocation(), P);
	UhConvert::Orientation(Transform.GetRotation(), Q);
	Api->uh_session_set_object_pose(AsId(SessionId), Index, P, Q);
}

// Registrations close here; the scene is built and its meshes packed on a worker thread (seconds
// the first time, the cache in Saved/UnrealHaptics after), so the game thread never hitches.
void AHapticManager::BeginBuild()
{
	const FUhApi* Api = FUhApi::Get();
	if (Api == nullptr)
	{
		Fail(TEXT("libuh could not be loaded (see LogUnrealHaptics)"));
		return;
	}
	FUhSessionRequest Request;
	Request.ScenePath = UhPaths::ResolveProjectFile(SceneFile.FilePath);
	Request.Objects = MoveTemp(Objects);
	Request.SceneObjectsToRemove = SceneObjectsToRemove;
	Request.Watched = Watched;
	Request.bHasTool = bHasTool;
	Request.Tool = Tool;
	Request.HapticHz = bOverrideHapticRate ? HapticHz : 0.0;
	Request.CollisionHz = bOverrideCollisionRate ? CollisionHz : -1.0;
	Request.bRaisePriority = bRaisePriority;
	Request.CacheDir = FPaths::ConvertRelativePathToFull(FPaths::Combine(FPaths::ProjectSavedDir(), TEXT("UnrealHaptics")));
	IFileManager::Get().MakeDirectory(*Request.CacheDir, true);
	State = EUhSessionState::Building;
	UE_LOG(LogUnrealHaptics, Log, TEXT("%s: building the session (%d objects, scene %s, cache %s)"), *GetName(), Request.Objects.Num(),
		Request.ScenePath.IsEmpty() ? TEXT("libuh's default") : *Request.ScenePath, *Request.CacheDir);
	OnPackingStarted.Broadcast();
	PendingBuild = Async(EAsyncExecution::Thread, [Api, Request = MoveTemp(Request)]() -> TSharedPtr<FUhSessionBuild>
		{ return MakeShared<FUhSessionBuild>(UhBuildSession(*Api, Request)); });
}

void AHapticManager::FinishBuild(FUhSessionBuild& Build)
{
	OnPackingFinished.Broadcast();
	for (const FString& Warning : Build.Warnings)
	{
		UE_LOG(LogUnrealHaptics, Warning, TEXT("%s: %s"), *GetName(), *Warning);
	}
	if (Build.Session.bits == 0)
	{
		Fail(Build.Error);
		return;
	}
	SessionId = Build.Session.bits;
	SessionObjectNames = Build.ObjectNames;
	FString Error;
	if (!UhStartSession(*FUhApi::Get(), AsId(SessionId), &UhDispatchTick, &HookTable, Error))
	{
		CloseSession();
		Fail(Error);
		return;
	}
	State = EUhSessionState::Running;
	UE_LOG(LogUnrealHaptics, Log, TEXT("%s: session running (%d objects, %d haptic tick hooks)"), *GetName(), SessionObjectNames.Num(),
		HookTable.Count);
	OnSessionStarted.Broadcast();
}

void AHapticManager::Fail(const FString& Message)
{
	State = EUhSessionState::Failed;
	LastError = Message;
	UE_LOG(LogUnrealHaptics, Error, TEXT("%s: %s"), *GetName(), *Message);
	OnSessionFailed.Broadcast(Message);
}

void AHapticManager::Tick(float DeltaSeconds)
{
	Super::Tick(DeltaSeconds);
	if (State == EUhSessionState::Idle)
	{
		BeginBuild();  // every actor's BeginPlay has registered its part by now
	}
	if (State == EUhSessionState::Building && PendingBuild.IsReady())
	{
		const TSharedPtr<FUhSessionBuild> Build = PendingBuild.Get();
		PendingBuild = TFuture<TSharedPtr<FUhSessionBuild>>();
		FinishBuild(*Build);
	}
	if (State == EUhSessionState::Running)
	{
		PollState();
		PollEvents();
		DrawDebug();
		StopIfEndedByItself();
	}
}

// A device that faulted or a libuh thread that ended has had the force zeroed already: the
// session is stopped (its report kept, OnSessionStopped) and the cause reported (OnSessionFailed),
// rather than the level running on with a tool that no longer moves or pushes.
void AHapticManager::StopIfEndedByItself()
{
	const FUhApi* Api = FUhApi::Get();
	int32 Ended = 0;
	if (Api->uh_session_ended(AsId(SessionId), &Ended) != UH_OK || Ended == 0)
	{
		return;
	}
	const FString Why = Api->uh_session_stop(AsId(SessionId)) != UH_OK ? Api->LastError() : FString(TEXT("the session ended by itself"));
	StopHaptics();
	Fail(Why);
}

void AHapticManager::PollState()
{
	uh_state S{};
	S.struct_size = sizeof S;
	if (FUhApi::Get()->uh_session_poll(AsId(SessionId), &S) != UH_OK)
	{
		return;
	}
	Newest.TimeSeconds = S.time_s;
	Newest.ToolPosition = UhConvert::ToUnrealPosition(S.tool_position);
	Newest.ToolOrientation = UhConvert::ToUnrealOrientation(S.tool_orientation).Rotator();
	Newest.Force = UhConvert::ToUnrealForce(S.force);
	Newest.Torque = UhConvert::ToUnrealTorque(S.torque);
	Newest.ContactPairs = S.contact_pairs;
	Newest.HapticTicks = static_cast<int64>(S.haptic_ticks);
	Newest.MissedDeadlines = static_cast<int64>(S.missed_deadlines);
	Newest.Buttons = static_cast<int32>(S.buttons);
	OnMoveOnHapticTick.Broadcast(Newest.ToolPosition, Newest.ToolOrientation, Newest.Buttons);
	OnForceOnHapticTick.Broadcast(Newest.Force, Newest.Torque);
}

void AHapticManager::PollEvents()
{
	uh_contact_event E{};
	E.struct_size = sizeof E;
	int32 Has = 0;
	while (IsRunning() && FUhApi::Get()->uh_session_poll_event(AsId(SessionId), &E, &Has) == UH_OK && Has != 0)
	{
		const FUhContact Contact = UhToContact(E, SessionObjectNames);
		OnNativeContact.Broadcast(Contact);
		FUhContactEvent Event;
		Event.ObjectName = Contact.ObjectName;
		Event.bBegin = Contact.bBegin;
		Event.Pairs = Contact.Pairs;
		Event.Volume = Contact.Volume;
		OnContact.Broadcast(Event);  // a handler may stop the session: the loop checks IsRunning()
	}
}

void AHapticManager::DrawDebug() const
{
#if ENABLE_DRAW_DEBUG
	if (!bDrawDebug)
	{
		return;
	}
	const FVector ToolAt = Newest.ToolPosition;
	const FColor Color = Newest.ContactPairs > 0 ? FColor::Red : FColor::Green;
	DrawDebugCoordinateSystem(GetWorld(), ToolAt, Newest.ToolOrientation, 2.0f, false, -1.0f, 0, 0.1f);
	DrawDebugSphere(GetWorld(), ToolAt, 0.5f, 8, Color);
	if (!Newest.Force.IsNearlyZero())
	{
		DrawDebugDirectionalArrow(GetWorld(), ToolAt, ToolAt + Newest.Force * DebugCentimetersPerNewton, 1.0f, FColor::Yellow, false, -1.0f, 0, 0.1f);
	}
	// the proxy (the tool's constrained pose) is not drawn: libuh's state does not carry it yet
#endif
}

// A build still running is waited for (the game thread blocks for the rest of the packing) and
// its session closed unstarted.
void AHapticManager::DiscardPendingBuild()
{
	if (!PendingBuild.IsValid())
	{
		return;
	}
	UE_LOG(LogUnrealHaptics, Log, TEXT("%s: stopped while the session was built: waiting for the packing to finish"), *GetName());
	const TSharedPtr<FUhSessionBuild> Build = PendingBuild.Get();
	PendingBuild = TFuture<TSharedPtr<FUhSessionBuild>>();
	OnPackingFinished.Broadcast();
	if (const FUhApi* Api = FUhApi::Get(); Api != nullptr && Build->Session.bits != 0)
	{
		Api->uh_session_destroy(Build->Session);
	}
}

FString AHapticManager::StopHaptics()
{
	DiscardPendingBuild();
	if (State == EUhSessionState::Running)
	{
		const FUhApi* Api = FUhApi::Get();
		Api->uh_session_stop(AsId(SessionId));  // zero force, every thread joined
		const char* Json = nullptr;
		if (Api->uh_session_report_json(AsId(SessionId), &Json) == UH_OK)
		{
			Report = UTF8_TO_TCHAR(Json);
		}
		PollState();  // the last state: the zero force the device got
		State = EUhSessionState::Stopped;
		UE_LOG(LogUnrealHaptics, Log, TEXT("%s: session stopped"), *GetName());
		OnSessionStopped.Broadcast(Report);
	}
	else if (State == EUhSessionState::Idle || State == EUhSessionState::Building)
	{
		State = EUhSessionState::Stopped;  // never starts now
	}
	return Report;
}

void AHapticManager::CloseSession()
{
	if (const FUhApi* Api = FUhApi::Get(); Api != nullptr && SessionId != 0)
	{
		Api->uh_session_destroy(AsId(SessionId));  // stops first if it runs
	}
	SessionId = 0;
}

void AHapticManager::EndPlay(const EEndPlayReason::Type Reason)
{
	StopHaptics();
	CloseSession();
	Super::EndPlay(Reason);
}

// Should EndPlay never come (an actor destroyed without it), the session still stops and closes.
void AHapticManager::BeginDestroy()
{
	if (PendingBuild.IsValid() || SessionId != 0)
	{
		DiscardPendingBuild();
		CloseSession();
		State = EUhSessionState::Stopped;
	}
	Super::BeginDestroy();
}
