// UnrealHapticsForceComp (the paper's force module, ForceComp): UForceComponent (the tool's force
// law, editor properties), AForceController and ABridgingController (the paper's wiring), over
// the HapticManager.
using UnrealBuildTool;

public class UnrealHapticsForceComp : ModuleRules
{
	public UnrealHapticsForceComp(ReadOnlyTargetRules Target) : base(Target)
	{
		PCHUsage = PCHUsageMode.UseExplicitOrSharedPCHs;
		PublicDependencyModuleNames.AddRange(new string[] { "Core", "CoreUObject", "Engine", "UnrealHapticsHaptico" });
	}
}
