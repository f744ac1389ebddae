#include "UhSessionBuilder.h"

#include "UhApi.h"

#include <cstdio>
#include <cstring>

namespace
{
	// FNV-1a: the key of a packed static mesh in the cache (its triangles, sphere count and the
	// library's version, whose packer may differ).
	uint64 HashBytes(const void* Data, size_t Size, uint64 Hash)
	{
		const uint8* Bytes = static_cast<const uint8*>(Data);
		for (size_t I = 0; I < Size; ++I)
		{
			Hash = (Hash ^ Bytes[I]) * 1099511628211ull;
		}
		return Hash;
	}

	FString CachePath(const FUhApi& Api, const FUhObjectSpec& O, const FString& CacheDir)
	{
		const char* Version = Api.uh_version_string();
		uint64 Hash = 14695981039346656037ull;
		Hash = HashBytes(O.Vertices.GetData(), sizeof(double) * O.Vertices.Num(), Hash);
		Hash = HashBytes(O.Indices.GetData(), sizeof(int32) * O.Indices.Num(), Hash);
		Hash = HashBytes(&O.Spheres, sizeof O.Spheres, Hash);
		Hash = HashBytes(Version, std::strlen(Version), Hash);
		char Key[40];
		std::snprintf(Key, sizeof Key, "-%016llx.ist", static_cast<unsigned long long>(Hash));
		return CacheDir + TEXT("/") + O.Name + UTF8_TO_TCHAR(Key);
	}

	FString Failure(const FUhApi& Api, const FString& What)
	{
		return What + TEXT(": ") + Api.LastError();
	}

	// A static mesh's triangles as a tree: loaded from the cache when packed before, else packed
	// (seconds) and saved there. A zero id on failure (Out.Error set).
	uh_tree_id CachedTree(const FUhApi& Api, const FUhObjectSpec& O, const FString& CacheDir, FUhSessionBuild& Out)
	{
		const FString Path = CacheDir.IsEmpty() ? FString() : CachePath(Api, O, CacheDir);
		const FTCHARToUTF8 Utf8Path(*Path);
		uh_tree_id Tree{};
		if (!Path.IsEmpty() && Api.uh_tree_load(Utf8Path.Get(), &Tree) == UH_OK)
		{
			return Tree;
		}
		uh_tree_build_def Def = FUhApi::Defaults(Api.uh_tree_build_def_init);
		Def.spheres = O.Spheres;
		if (Api.uh_tree_build_from_arrays(O.Vertices.GetData(), O.Vertices.Num() / 3, O.Indices.GetData(), O.Indices.Num() / 3,
				&Def, &Tree) != UH_OK)
		{
			Out.Error = Failure(Api, TEXT("uh_tree_build_from_arrays '") + O.Name + TEXT("'"));
			return uh_tree_id{};
		}
		if (!Path.IsEmpty() && Api.uh_tree_save(Tree, Utf8Path.Get()) != UH_OK)
		{
			Out.Warnings.Add(Failure(Api, TEXT("packing not cached")));
		}
		return Tree;
	}

	bool AddObject(const FUhApi& Api, uh_scene_id Scene, const FUhSessionRequest& Request, const FUhObjectSpec& O,
		FUhSessionBuild& Out)
	{
		uh_object_def Def = FUhApi::Defaults(Api.uh_object_def_init);
		const FTCHARToUTF8 Name(*O.Name);
		const FTCHARToUTF8 Ist(*O.IstPath);
		const FTCHARToUTF8 Mesh(*O.MeshPath);
		uh_tree_id Tree{};
		Def.name = Name.Get();
		Def.shape.spheres = O.Spheres;
		if (!O.IstPath.IsEmpty())
		{
			Def.shape.ist_path = Ist.Get();
		}
		else if (!O.MeshPath.IsEmpty())
		{
			Def.shape.mesh_path = Mesh.Get();  // packed by libuh, cached in the session's cache_dir
			Def.shape.meters_per_unit = O.MeshMetersPerUnit;
		}
		else if ((Tree = CachedTree(Api, O, Request.CacheDir, Out)).bits == 0)
		{
			return false;
		}
		Def.shape.tree = Tree;
		for (int32 I = 0; I < 3; ++I)
		{
			Def.position[I] = O.Position[I];
		}
		for (int32 I = 0; I < 4; ++I)
		{
			Def.orientation[I] = O.Orientation[I];
		}
		// a volume's watcher never unwatches anything: an unwatched object does not push back
		Def.watch = (O.bWatch || Request.Watched.Contains(O.Name)) ? 1 : 0;
		const bool bAdded = Api.uh_scene_add_object(Scene, &Def, nullptr) == UH_OK;
		if (!bAdded)
		{
			Out.Error = Failure(Api, TEXT("uh_scene_add_object '") + O.Name + TEXT("'"));
		}
		Api.uh_tree_destroy(Tree);  // the scene holds its own reference
		return bAdded;
	}

	bool SetTool(const FUhApi& Api, uh_scene_id Scene, const FUhToolSpec& Tool, FUhSessionBuild& Out)
	{
		uh_tool_def Def = FUhApi::Defaults(Api.uh_tool_def_init);
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
		if (Api.uh_scene_set_tool(Scene, &Def) != UH_OK)
		{
			Out.Error = Failure(Api, TEXT("uh_scene_set_tool"));
			return false;
		}
		return true;
	}

	// The scene: the file (or the default), the level's objects, then the file's objects the level
	// replaces (after, so the scene never runs empty), the volumes' watched names and the tool.
	bool BuildScene(const FUhApi& Api, uh_scene_id Scene, const FUhSessionRequest& Request, FUhSessionBuild& Out)
	{
		for (const FUhObjectSpec& O : Request.Objects)
		{
			if (!AddObject(Api, Scene, Request, O, Out))
			{
				return false;
			}
		}
		for (const FString& Name : Request.SceneObjectsToRemove)
		{
			if (Api.uh_scene_remove_object(Scene, FTCHARToUTF8(*Name).Get()) != UH_OK)
			{
				Out.Warnings.Add(Failure(Api, TEXT("SceneObjectsToRemove '") + Name + TEXT("' ignored")));
			}
		}
		for (const FString& Name : Request.Watched)
		{
			if (Api.uh_scene_watch(Scene, FTCHARToUTF8(*Name).Get(), 1) != UH_OK)
			{
				Out.Warnings.Add(Failure(Api, TEXT("watcher of '") + Name + TEXT("' ignored")));
			}
		}
		if (Request.bHasTool && Request.Tool.MeshPath.IsEmpty())
		{
			Out.Warnings.Add(TEXT("the ForceComponent names no tool mesh: the scene's tool and force settings are kept"));
			return true;
		}
		return !Request.bHasTool || SetTool(Api, Scene, Request.Tool, Out);
	}
}

FUhSessionBuild UhBuildSession(const FUhApi& Api, const FUhSessionRequest& Request)
{
	FUhSessionBuild Out;
	uh_scene_id Scene{};
	const FTCHARToUTF8 ScenePath(*Request.ScenePath);
	if (Api.uh_scene_load(Request.ScenePath.IsEmpty() ? nullptr : ScenePath.Get(), &Scene) != UH_OK)
	{
		Out.Error = Failure(Api, TEXT("uh_scene_load '") + Request.ScenePath + TEXT("'"));
		return Out;
	}
	if (BuildScene(Api, Scene, Request, Out))
	{
		uh_session_def Def = FUhApi::Defaults(Api.uh_session_def_init);
		const FTCHARToUTF8 CacheDir(*Request.CacheDir);
		Def.haptic_hz = Request.HapticHz > 0.0 ? Request.HapticHz : 0.0;
		Def.collision_hz = Request.CollisionHz;
		Def.raise_priority = Request.bRaisePriority ? 1 : 0;
		Def.cache_dir = Request.CacheDir.IsEmpty() ? nullptr : CacheDir.Get();
		if (Api.uh_session_create_checked(UH_API_VERSION, Scene, &Def, &Out.Session) != UH_OK)
		{
			Out.Session = uh_session_id{};
			Out.Error = Failure(Api, TEXT("uh_session_create"));
		}
	}
	Api.uh_scene_destroy(Scene);  // the session holds a copy
	int32 Count = 0;
	if (Out.Session.bits != 0 && Api.uh_session_object_count(Out.Session, &Count) == UH_OK)
	{
		for (int32 I = 0; I < Count; ++I)
		{
			const char* Name = "";
			Api.uh_session_object_name(Out.Session, I, &Name);
			Out.ObjectNames.Add(UTF8_TO_TCHAR(Name));
		}
	}
	return Out;
}

bool UhStartSession(const FUhApi& Api, uh_session_id Session, uh_tick_fn Fn, void* User, FString& OutError)
{
	if (Api.uh_session_set_tick_callback(Session, Fn, User) != UH_OK)
	{
		OutError = Failure(Api, TEXT("uh_session_set_tick_callback"));
		return false;
	}
	if (Api.uh_session_start(Session) != UH_OK)
	{
		OutError = Failure(Api, TEXT("uh_session_start"));
		return false;
	}
	return true;
}

void UhToTickState(const uh_state& In, FUhTickState& Out)
{
	Out.TimeSeconds = In.time_s;
	for (int32 I = 0; I < 3; ++I)
	{
		Out.ToolPosition[I] = In.tool_position[I];
		Out.Force[I] = In.force[I];
		Out.Torque[I] = In.torque[I];
	}
	for (int32 I = 0; I < 4; ++I)
	{
		Out.ToolOrientation[I] = In.tool_orientation[I];
	}
	Out.ContactPairs = In.contact_pairs;
	Out.HapticTicks = In.haptic_ticks;
	Out.Buttons = In.buttons;
}

void UhDispatchTick(void* User, const uh_state* State)
{
	const FUhHapticHookTable& Table = *static_cast<const FUhHapticHookTable*>(User);
	if (Table.Count == 0)
	{
		return;
	}
	FUhTickState Converted;
	UhToTickState(*State, Converted);
	for (int32 I = 0; I < Table.Count; ++I)
	{
		Table.Fns[I](Table.Users[I], Converted);
	}
}

FUhContact UhToContact(const uh_contact_event& In, const TArray<FString>& ObjectNames)
{
	FUhContact Out;
	Out.ObjectName = In.object >= 0 && In.object < ObjectNames.Num() ? ObjectNames[In.object] : FString();
	Out.Tool = In.tool;
	Out.bBegin = In.kind == UH_CONTACT_BEGIN;
	Out.TimeSeconds = In.time_s;
	Out.Volume = In.volume;
	Out.Pairs = In.pairs;
	return Out;
}
