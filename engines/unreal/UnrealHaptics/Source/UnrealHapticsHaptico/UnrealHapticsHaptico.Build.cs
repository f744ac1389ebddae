// UnrealHapticsHaptico (the paper's device module, Haptico): libuh loaded at run time (UhApi),
// the session built off the game thread (UhSessionBuilder), unit conversion (UhConvert) and
// AHapticManager, which owns the libuh session and its haptic thread. uh.h is private to this
// module (UhLibrary is a private dependency): other code reaches libuh only through the manager.
using UnrealBuildTool;

public class UnrealHapticsHaptico : ModuleRules
{
	public UnrealHapticsHaptico(ReadOnlyTargetRules Target) : base(Target)
	{
		PCHUsage = PCHUsageMode.UseExplicitOrSharedPCHs;
		PublicDependencyModuleNames.AddRange(new string[] { "Core", "CoreUObject", "Engine" });
		PrivateDependencyModuleNames.AddRange(new string[] { "Projects", "UhLibrary" });
	}
}
