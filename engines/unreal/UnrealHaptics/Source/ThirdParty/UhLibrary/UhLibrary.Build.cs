// The third-party module that stages libuh, the UnrealHaptics C API: its header (include/uh/uh.h)
// and the shared library for each platform, copied here by stage-libuh.sh from a build of the
// repository (Linux: build/release/src/capi/libuh.so; Windows x64: the mingw-w64 build's uh.dll, build/windows/bin/uh.dll).
// Haptico loads the library at run time and resolves its functions by name (UhApi), so no import
// library (which MSVC and MinGW make differently) is needed; the library only has to be staged
// beside the binaries (RuntimeDependencies).
using System.IO;
using UnrealBuildTool;

public class UhLibrary : ModuleRules
{
	public UhLibrary(ReadOnlyTargetRules Target) : base(Target)
	{
		Type = ModuleType.External;
		PublicSystemIncludePaths.Add(Path.Combine(ModuleDirectory, "include"));
		string Lib = Path.Combine(ModuleDirectory, "lib");
		if (Target.Platform == UnrealTargetPlatform.Linux)
		{
			RuntimeDependencies.Add("$(BinaryOutputDir)/libuh.so", Path.Combine(Lib, "Linux", "libuh.so"));
			PublicDefinitions.Add("UH_LIBRARY_NAME=\"libuh.so\"");
		}
		else if (Target.Platform == UnrealTargetPlatform.Win64)
		{
			RuntimeDependencies.Add("$(BinaryOutputDir)/uh.dll", Path.Combine(Lib, "Win64", "uh.dll"));
			PublicDefinitions.Add("UH_LIBRARY_NAME=\"uh.dll\"");
		}
	}
}
