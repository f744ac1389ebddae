#include "HapticManager.h"

#include "EngineUtils.h"
#include "Misc/ScopeExit.h"
#include "UhApi.h"
#include "UhConvert.h"

DEFINE_LOG_CATEGORY_STATIC(LogHapticManager, Log, All);

AHapticManager::AHapticManager()
{
	PrimaryActorTick.bCanEverTick = true;
	PrimaryActorTick.TickGroup = TG_PrePhysics;
}

AHapticManager* AHapticManager::FindIn(UWorld* World)
{
	TActorIterator<AHapticManager> It(World);
	return It ? *It : nullptr;
}

void AHapticManager::RegisterObject(FUhObjectSpec Spec)
{
	if (Session != nullptr)
	{
		UE_LOG(LogHapticManager, Warning, TEXT("%s: the session runs already; objects are registered in BeginPlay"), *Spec.Name);
		return;
	}
	Objects.Add(MoveTemp(Spec));
}

int32 AHapticManager::ObjectIndex(const FString& Name) const
{
	return SessionObjectNames.IndexOfByKey(Name);
}

void AHapticManager::SetObjectPose(const FString& Name, const FTransform& Transform)
{
	const FUhApi* Api = FUhApi::Get();
	const int32 Index = ObjectIndex(Name);
	if (Api == nullptr || Session == nullptr || Index == INDEX_NONE)
	{
		return;
	}
	double P[3], Q[4];
	UhConvert::Position(Transform.GetLocation(), P);
	UhConvert::Orientation(Transform.GetRotation(), Q);
	Api->uh_session_set_object_pose(Session, Index, P, Q);
}

// Builds the scene (file or default, the registered objects and tool, the watched pairs), opens the
// session, binds the haptic-thread callback and starts. Every failure is logged with libuh's message.
bool AHapticManager::StartSession()
{
	const FUhApi* Api = FUhApi::Get();
	if (Api == nullptr)
	{
		return false;
	}
	const auto Fail = [&](const TCHAR* Call)
	{
		UE_LOG(LogHapticManager, Error, TEXT("%s: %s"), Call, *Api->LastError());
		return false;
	};
	uh_scene* Scene = nullptr;
	const FTCHARToUTF8 ScenePath(*SceneFile.FilePath);
	if (Api->uh_scene_load(SceneFile.FilePath.IsEmpty() ? nullptr : ScenePath.Get(), &Scene) != UH_OK)
	{
		return Fail(TEXT("uh_scene_load"));
	}
	ON_SCOPE_EXIT { Api->uh_scene_free(Scene); };

	TArray<FString> Added;
	for (const FUhObjectSpec& O : Objects)
	{
		uh_object_def Def = Api->uh_default_object_def();
		const FTCHARToUTF8 Name(*O.Name);
		const FTCHARToUTF8 Ist(*O.IstPath);
		Def.name = Name.Get();
		if (!O.IstPath.IsEmpty())
		{
			Def.shape.ist_path = Ist.Get();
		}
		else
		{
			Def.shape.vertices = O.Vertices.GetData();
			Def.shape.vertex_count = O.Vertices.Num() / 3;
			Def.shape.indices = O.Indices.GetData();
			Def.shape.triangle_count = O.Indices.Num() / 3;
		}
		Def.shape.spheres = O.Spheres;
		FMemory::Memcpy(Def.position, O.Position, sizeof Def.position);
		FMemory::Memcpy(Def.orientation, O.Orientation, sizeof Def.orientation);
		Def.watch = O.bWatch ? 1 : 0;
		if (Api->uh_scene_add_object(Scene, &Def, nullptr) != UH_OK)
		{
			return Fail(*FString::Printf(TEXT("uh_scene_add_object '%s'"), *O.Name));
		}
		Added.Add(O.Name);
	}
	// the scene file's objects that the level replaces (after the level's own were added, so the
	// scene never runs empty)
	for (const FString& Name : Added.Num() > 0 ? SceneObjectsToRemove : TArray<FString>())
	{
		if (Api->uh_scene_remove_object(Scene, TCHAR_TO_UTF8(*Name)) != UH_OK)
		{
			return Fail(*FString::Printf(TEXT("uh_scene_remove_object '%s'"), *Name));
		}
	}
	if (Watched.Num() > 0)
	{
		for (const FString& Name : Added)
		{
			Api->uh_scene_watch(Scene, TCHAR_TO_UTF8(*Name), Watched.Contains(Name) ? 1 : 0);
		}
	}
	if (bHasTool && !Tool.MeshPath.IsEmpty())
	{
		uh_tool_def Def = Api->uh_default_tool_def();
		const FTCHARToUTF8 Mesh(*Tool.MeshPath);
		const FTCHARToUTF8 Driver(*Tool.DeviceDriver);
		const FTCHARToUTF8 Config(*Tool.DeviceConfigJson);
		if (Tool.MeshPath.EndsWith(TEXT(".ist")))
		{
			Def.shape.ist_path = Mesh.Get();
		}
		else
		{
			Def.shape.mesh_path = Mesh.Get();
		}
		Def.shape.meters_per_unit = Tool.MetersPerUnit;
		Def.shape.spheres = Tool.Spheres;
		Def.mode = Tool.bThreeDof ? UH_FORCE_3DOF : UH_FORCE_6DOF;
		Def.law = Tool.bPaperLaw ? UH_FORCE_LAW_PAPER : UH_FORCE_LAW_GRADIENT;
		Def.stiffness = Tool.Stiffness;
		Def.force_scale = Tool.ForceScale;
		Def.damping = Tool.Damping;
		Def.mass_kg = Tool.MassKg;
		Def.max_force_n = Tool.MaxForceN;
		Def.max_torque_nm = Tool.MaxTorqueNm;
		Def.device_driver = Tool.DeviceDriver.IsEmpty() ? "sim-raster" : Driver.Get();
		Def.device_config_json = Tool.DeviceConfigJson.IsEmpty() ? nullptr : Config.Get();
		if (Api->uh_scene_set_tool(Scene, &Def) != UH_OK)
		{
			return Fail(TEXT("uh_scene_set_tool"));
		}
	}
	else if (bHasTool)
	{
		UE_LOG(LogHapticManager, Warning, TEXT("the ForceComponent names no tool mesh: the scene's tool and force settings are kept"));
	}
	if (HapticHz > 0.0 || CollisionHz >= 0.0)
	{
		if (Api->uh_scene_set_rates(Scene, HapticHz > 0.0 ? HapticHz : 1000.0, CollisionHz >= 0.0 ? CollisionHz : 1000.0) != UH_OK)
		{
			return Fail(TEXT("uh_scene_set_rates"));
		}
	}
	uh_session_def SessionDef = Api->uh_default_session_def();
	SessionDef.raise_priority = bRaisePriority ? 1 : 0;
	if (Api->uh_session_create_checked(UH_API_VERSION, Scene, &SessionDef, &Session) != UH_OK)
	{
		Session = nullptr;
		return Fail(TEXT("uh_session_create"));
	}
	int32 Count = 0;
	Api->uh_session_object_count(Session, &Count);
	for (int32 I = 0; I < Count; ++I)
	{
		const char* Name = nullptr;
		Api->uh_session_object_name(Session, I, &Name);
		SessionObjectNames.Add(UTF8_TO_TCHAR(Name));
	}
	if (Api->uh_session_set_tick_callback(Session, &AHapticManager::OnHapticTick, this) != UH_OK ||
		Api->uh_session_start(Session) != UH_OK)
	{
		Fail(TEXT("uh_session_start"));
		CloseSession();
		return false;
	}
	bStarted = true;
	return true;
}

// The haptic thread, after every tick: only the native delegates (real-time code bound before play).
void AHapticManager::OnHapticTick(void* User, const uh_state* State)
{
	AHapticManager* Self = static_cast<AHapticManager*>(User);
	Self->MoveOnHapticTick.Broadcast(*State);
	Self->ForceOnHapticTick.Broadcast(*State);
}

void AHapticManager::Tick(float DeltaSeconds)
{
	Super::Tick(DeltaSeconds);
	if (!bTried)
	{
		bTried = true;  // every actor's BeginPlay has registered its part by now
		StartSession();
	}
	const FUhApi* Api = FUhApi::Get();
	if (Api == nullptr || Session == nullptr || !bStarted)
	{
		return;
	}
	uh_state S{};
	S.struct_size = sizeof S;
	if (Api->uh_session_poll(Session, &S) == UH_OK)
	{
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
	uh_contact_event E{};
	E.struct_size = sizeof E;
	int32 Has = 0;
	while (Api->uh_session_poll_event(Session, &E, &Has) == UH_OK && Has != 0)
	{
		OnContact.Broadcast(E);
	}
}

FString AHapticManager::StopHaptics()
{
	const FUhApi* Api = FUhApi::Get();
	if (Api != nullptr && Session != nullptr && Report.IsEmpty())
	{
		Api->uh_session_stop(Session);  // zero force, every thread joined
		const char* Json = nullptr;
		if (Api->uh_session_report_json(Session, &Json) == UH_OK)
		{
			Report = UTF8_TO_TCHAR(Json);
		}
		Newest.Force = FVector::ZeroVector;
		Newest.Torque = FVector::ZeroVector;
	}
	return Report;
}

void AHapticManager::CloseSession()
{
	const FUhApi* Api = FUhApi::Get();
	if (Api != nullptr && Session != nullptr)
	{
		Api->uh_session_close(Session);  // stops first if it runs
	}
	Session = nullptr;
	bStarted = false;
}

void AHapticManager::EndPlay(const EEndPlayReason::Type Reason)
{
	StopHaptics();
	CloseSession();
	Super::EndPlay(Reason);
}
