// ForceComp (the paper's force module): UForceComponent (the tool's force law, editor properties),
// AForceController and ABridgingController (the paper's wiring), over Haptico's manager.
using UnrealBuildTool;

public class ForceComp : ModuleRules
{
	public ForceComp(ReadOnlyTargetRules Target) : base(Target)
	{
		PCHUsage = PCHUsageMode.UseExplicitOrSharedPCHs;
		PublicDependencyModuleNames.AddRange(new string[] { "Core", "CoreUObject", "Engine", "Haptico", "UhLibrary" });
	}
}
