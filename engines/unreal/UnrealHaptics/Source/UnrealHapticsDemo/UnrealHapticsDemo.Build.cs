// UnrealHapticsDemo: AUnrealHapticsDemo, an actor that, dropped into any level, spawns the paper's
// parts around libuh's default scene (the bunny, a stylus on a simulated device, the controllers).
using UnrealBuildTool;

public class UnrealHapticsDemo : ModuleRules
{
	public UnrealHapticsDemo(ReadOnlyTargetRules Target) : base(Target)
	{
		PCHUsage = PCHUsageMode.UseExplicitOrSharedPCHs;
		PublicDependencyModuleNames.AddRange(new string[] { "Core", "CoreUObject", "Engine", "UnrealHapticsHaptico", "UnrealHapticsCollette", "UnrealHapticsForceComp" });
		PrivateDependencyModuleNames.AddRange(new string[] { "Projects" });
	}
}
