#include "UhApi.h"

#include "HAL/PlatformProcess.h"
#include "Interfaces/IPluginManager.h"
#include "Misc/Paths.h"

DEFINE_LOG_CATEGORY_STATIC(LogUhApi, Log, All);

namespace
{
	// The staged library: beside the game's binaries (RuntimeDependencies), else in the plugin's
	// third-party folder (editor builds).
	void* LoadLibuh()
	{
		TArray<FString> Candidates;
		Candidates.Add(FPaths::Combine(FPlatformProcess::GetModulesDirectory(), TEXT(UH_LIBRARY_NAME)));
		if (const TSharedPtr<IPlugin> Plugin = IPluginManager::Get().FindPlugin(TEXT("UnrealHaptics")))
		{
			const FString Lib = FPaths::Combine(Plugin->GetBaseDir(), TEXT("Source/ThirdParty/UhLibrary/lib"));
			Candidates.Add(FPaths::Combine(Lib, PLATFORM_WINDOWS ? TEXT("Win64") : TEXT("Linux"), TEXT(UH_LIBRARY_NAME)));
		}
		for (const FString& Path : Candidates)
		{
			if (void* Handle = FPlatformProcess::GetDllHandle(*Path))
			{
				return Handle;
			}
		}
		UE_LOG(LogUhApi, Error, TEXT("libuh not found (looked in %s); run engines/unreal/UnrealHaptics/stage-libuh.sh"),
			*FString::Join(Candidates, TEXT(", ")));
		return nullptr;
	}

	bool Resolve(void* Handle, FUhApi& Api)
	{
		bool bAll = true;
#define UH_RESOLVE(Name)                                                                             \
	Api.Name = reinterpret_cast<decltype(Api.Name)>(FPlatformProcess::GetDllExport(Handle, TEXT(#Name))); \
	if (Api.Name == nullptr)                                                                         \
	{                                                                                                \
		UE_LOG(LogUhApi, Error, TEXT("libuh has no function %s (another version?)"), TEXT(#Name));   \
		bAll = false;                                                                                \
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
			UE_LOG(LogUhApi, Error, TEXT("libuh speaks API version %d, the plugin was built for %d"), Api.uh_api_version(),
				UH_API_VERSION);
			return nullptr;
		}
		UE_LOG(LogUhApi, Log, TEXT("libuh %s loaded"), UTF8_TO_TCHAR(Api.uh_version_string()));
		return &Api;
	}();
	return Loaded;
}
