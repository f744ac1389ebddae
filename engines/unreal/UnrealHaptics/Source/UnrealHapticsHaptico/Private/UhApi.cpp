#include "UhApi.h"

#include "HAL/PlatformProcess.h"
#include "Interfaces/IPluginManager.h"
#include "Misc/Paths.h"
#include "UnrealHapticsLog.h"

namespace
{
	// Where the library is looked for, in order: the plugin's Binaries/<Platform> (where UhLibrary's
	// RuntimeDependencies put it, in the editor and in a packaged game), the running executable's
	// folder, the project's Binaries/<Platform>, the engine's.
	TArray<FString> LibraryCandidates()
	{
		const FString Platform = FPlatformProcess::GetBinariesSubdirectory();
		TArray<FString> Folders;
		if (const TSharedPtr<IPlugin> Plugin = IPluginManager::Get().FindPlugin(TEXT("UnrealHaptics")))
		{
			Folders.Add(FPaths::Combine(Plugin->GetBaseDir(), TEXT("Binaries"), Platform));
		}
		Folders.Add(FPlatformProcess::GetModulesDirectory());
		Folders.Add(FPaths::Combine(FPaths::ProjectDir(), TEXT("Binaries"), Platform));
		Folders.Add(FPaths::Combine(FPaths::EngineDir(), TEXT("Binaries"), Platform));
		TArray<FString> Candidates;
		for (const FString& Folder : Folders)
		{
			Candidates.AddUnique(FPaths::ConvertRelativePathToFull(FPaths::Combine(Folder, TEXT(UH_LIBRARY_NAME))));
		}
		return Candidates;
	}

	void* LoadLibuh()
	{
		const TArray<FString> Candidates = LibraryCandidates();
		for (const FString& Path : Candidates)
		{
			if (!FPaths::FileExists(Path))
			{
				UE_LOG(LogUnrealHaptics, Verbose, TEXT("libuh: not in %s"), *Path);
				continue;
			}
			if (void* Handle = FPlatformProcess::GetDllHandle(*Path))
			{
				UE_LOG(LogUnrealHaptics, Log, TEXT("libuh: loaded %s"), *Path);
				return Handle;
			}
			// present but not loadable: on Linux usually a dependency missing (see the README's packaging)
			UE_LOG(LogUnrealHaptics, Error, TEXT("libuh: %s exists but does not load (a dependency missing?)"), *Path);
		}
		UE_LOG(LogUnrealHaptics, Error, TEXT("libuh: not found (looked in %s); run engines/unreal/UnrealHaptics/stage-libuh.sh and rebuild"),
			*FString::Join(Candidates, TEXT(", ")));
		return nullptr;
	}

	bool Resolve(void* Handle, FUhApi& Api)
	{
		bool bAll = true;
#define UH_RESOLVE(Name)                                                                                  \
	Api.Name = reinterpret_cast<decltype(Api.Name)>(FPlatformProcess::GetDllExport(Handle, TEXT(#Name))); \
	if (Api.Name == nullptr)                                                                              \
	{                                                                                                     \
		UE_LOG(LogUnrealHaptics, Error, TEXT("libuh has no function %s (another version?)"), TEXT(#Name)); \
		bAll = false;                                                                                     \
	}
		UH_API_FUNCTIONS(UH_RESOLVE)
#undef UH_RESOLVE
		return bAll;
	}
}

const FUhApi* FUhApi::Get()
{
	// resolved once, on first use (thread-safe static initialisation)
	static const FUhApi* const Loaded = []() -> const FUhApi*
	{
		static FUhApi Api;
		void* Handle = LoadLibuh();
		if (Handle == nullptr || !Resolve(Handle, Api))
		{
			return nullptr;
		}
		if (Api.uh_api_version() != UH_API_VERSION)
		{
			UE_LOG(LogUnrealHaptics, Error, TEXT("libuh speaks API version %d, the plugin was built for %d"), Api.uh_api_version(),
				UH_API_VERSION);
			return nullptr;
		}
		UE_LOG(LogUnrealHaptics, Log, TEXT("libuh %s, API version %d"), UTF8_TO_TCHAR(Api.uh_version_string()), UH_API_VERSION);
		return &Api;
	}();
	return Loaded;
}
