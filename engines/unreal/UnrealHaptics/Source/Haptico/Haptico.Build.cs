// Haptico (the paper's device module): the C API loaded at run time (UhApi), unit conversion, and
// AHapticManager, which owns the libuh session and its haptic thread.
using UnrealBuildTool;

public class Haptico : ModuleRules
{
	public Haptico(ReadOnlyTargetRules Target) : base(Target)
	{
		PCHUsage = PCHUsageMode.UseExplicitOrSharedPCHs;
		PublicDependencyModuleNames.AddRange(new string[] { "Core", "CoreUObject", "Engine", "Projects", "UhLibrary" });
	}
}
