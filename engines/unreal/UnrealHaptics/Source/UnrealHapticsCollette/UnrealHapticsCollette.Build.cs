// UnrealHapticsCollette (the paper's collision module, Collette): AColletteStaticMeshActor (a
// static mesh, a mesh file or an .ist as a collision object) and AColletteVolume (watched
// objects, OnCollision), over the HapticManager.
using UnrealBuildTool;

public class UnrealHapticsCollette : ModuleRules
{
	public UnrealHapticsCollette(ReadOnlyTargetRules Target) : base(Target)
	{
		PCHUsage = PCHUsageMode.UseExplicitOrSharedPCHs;
		PublicDependencyModuleNames.AddRange(new string[] { "Core", "CoreUObject", "Engine", "UnrealHapticsHaptico" });
	}
}
