// UnrealHapticsEditor: the plugin's editor side. While a HapticManager packs its meshes (the first
// Play In Editor of a level, or after a mesh changed; cached in Saved/UnrealHaptics after) a
// notification with a throbber says so.
using UnrealBuildTool;

public class UnrealHapticsEditor : ModuleRules
{
	public UnrealHapticsEditor(ReadOnlyTargetRules Target) : base(Target)
	{
		PCHUsage = PCHUsageMode.UseExplicitOrSharedPCHs;
		PrivateDependencyModuleNames.AddRange(new string[] { "Core", "CoreUObject", "Engine", "Slate", "SlateCore", "UnrealHapticsHaptico" });
	}
}
