// The third-party module that stages libuh, the UnrealHaptics C API: its header (include/uh/uh.h),
// the shared library of each platform with what it needs (lib/<Platform>/, listed in
// lib/<Platform>/files.txt) and the demo's data (data/), all copied here by stage-libuh.sh from a
// build of the repository and never committed. The libraries go to the plugin's
// Binaries/<Platform> (RuntimeDependencies: in the editor and in a packaged game), where Haptico
// loads libuh at run time and resolves its functions by name, so no import library (which MSVC
// and MinGW make differently) is needed.
using System.IO;
using EpicGames.Core;
using UnrealBuildTool;

public class UhLibrary : ModuleRules
{
	public UhLibrary(ReadOnlyTargetRules Target) : base(Target)
	{
		Type = ModuleType.External;
		string Header = Path.Combine(ModuleDirectory, "include", "uh", "uh.h");
		RequireStaged(Header);
		PublicSystemIncludePaths.Add(Path.Combine(ModuleDirectory, "include"));
		if (Target.Platform == UnrealTargetPlatform.Linux)
		{
			StageLibraries("Linux");
			PublicDefinitions.Add("UH_LIBRARY_NAME=\"libuh.so\"");
		}
		else if (Target.Platform == UnrealTargetPlatform.Win64)
		{
			StageLibraries("Win64");
			PublicDefinitions.Add("UH_LIBRARY_NAME=\"uh.dll\"");
		}
		// the demo actor's mesh, read at run time (staged as loose files, outside the .pak)
		string Data = Path.Combine(ModuleDirectory, "data");
		if (Directory.Exists(Data))
		{
			foreach (string File in Directory.GetFiles(Data))
			{
				RuntimeDependencies.Add(File, StagedFileType.NonUFS);
			}
		}
	}

	// libuh and the shared libraries stage-libuh.sh found it needs, into the plugin's Binaries.
	void StageLibraries(string Platform)
	{
		string Lib = Path.Combine(ModuleDirectory, "lib", Platform);
		string Manifest = Path.Combine(Lib, "files.txt");
		RequireStaged(Manifest);
		foreach (string Line in File.ReadAllLines(Manifest))
		{
			string Name = Line.Trim();
			if (Name.Length == 0)
			{
				continue;
			}
			RequireStaged(Path.Combine(Lib, Name));
			RuntimeDependencies.Add(Path.Combine("$(PluginDir)", "Binaries", Platform, Name), Path.Combine(Lib, Name));
		}
		// the staged libraries' licenses (Debian's copyright files), shipped with them
		string Licenses = Path.Combine(Lib, "licenses");
		if (Directory.Exists(Licenses))
		{
			foreach (string License in Directory.GetFiles(Licenses))
			{
				RuntimeDependencies.Add(License, StagedFileType.NonUFS);
			}
		}
	}

	static void RequireStaged(string FilePath)
	{
		if (!File.Exists(FilePath))
		{
			throw new BuildException("UnrealHaptics: {0} is missing: run engines/unreal/UnrealHaptics/stage-libuh.sh (after building libuh) before building the plugin", FilePath);
		}
	}
}
