// libuh's functions, resolved by name from the shared library the UhLibrary module stages
// (libuh.so / uh.dll in the plugin's Binaries/<Platform>). Loaded once per process; the library's
// API version is checked against the header's UH_API_VERSION. Every other class calls the C API
// through here: uh.h stays private to this module, so no code links against libuh directly (it has
// no import library; the plugin resolves its functions at run time).
#pragma once

#include "CoreMinimal.h"
#include "uh/uh.h"

// Every libuh function the plugin calls, once: declared as members below, resolved in UhApi.cpp.
// The contract test (engines/unreal/tests) resolves the same list from the built libuh.
#define UH_API_FUNCTIONS(X) \
	X(uh_version_string) \
	X(uh_api_version) \
	X(uh_last_error) \
	X(uh_tree_build_def_init) \
	X(uh_object_def_init) \
	X(uh_tool_def_init) \
	X(uh_session_def_init) \
	X(uh_tree_load) \
	X(uh_tree_build_from_arrays) \
	X(uh_tree_save) \
	X(uh_tree_destroy) \
	X(uh_scene_load) \
	X(uh_scene_destroy) \
	X(uh_scene_add_object) \
	X(uh_scene_remove_object) \
	X(uh_scene_watch) \
	X(uh_scene_set_tool) \
	X(uh_session_create_checked) \
	X(uh_session_set_tick_callback) \
	X(uh_session_start) \
	X(uh_session_poll) \
	X(uh_session_poll_event) \
	X(uh_session_set_object_pose) \
	X(uh_session_object_count) \
	X(uh_session_object_name) \
	X(uh_session_ended) \
	X(uh_session_stop) \
	X(uh_session_report_json) \
	X(uh_session_destroy)

struct FUhApi
{
#define UH_API_FUNCTION(Name) decltype(&::Name) Name = nullptr;
	UH_API_FUNCTIONS(UH_API_FUNCTION)
#undef UH_API_FUNCTION

	/** The loaded API, or nullptr (logged once) when the library is missing or of another version. */
	static const FUhApi* Get();

	/** A descriptor with libuh's defaults, as uh.h's inline uh_default_*() makes it, through the
	 *  resolved uh_*_init (e.g. Defaults(Api.uh_tool_def_init)). */
	template <typename TDef>
	static TDef Defaults(uh_status (*Init)(TDef*))
	{
		TDef Def{};
		Def.struct_size = sizeof(TDef);
		Init(&Def);
		return Def;
	}

	/** The calling thread's last libuh error as an FString (libuh keeps it per thread). */
	FString LastError() const { return UTF8_TO_TCHAR(uh_last_error()); }
};
