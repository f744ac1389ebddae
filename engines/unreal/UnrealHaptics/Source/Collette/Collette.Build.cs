// Collette (the paper's collision module): AColletteStaticMeshActor (a static mesh or .ist as a
// collision object) and AColletteVolume (watched pairs, OnCollision), over Haptico's manager.
using UnrealBuildTool;

public class Collette : ModuleRules
{
	public Collette(ReadOnlyTargetRules Target) : base(Target)
	{
		PCHUsage = PCHUsageMode.UseExplicitOrSharedPCHs;
		PublicDependencyModuleNames.AddRange(new string[] { "Core", "CoreUObject", "Engine", "Haptico", "UhLibrary" });
	}
}
