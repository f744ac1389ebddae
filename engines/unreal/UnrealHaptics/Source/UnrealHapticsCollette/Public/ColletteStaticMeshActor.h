// AColletteStaticMeshActor (the paper's ColletteStaticMeshActor): a static mesh actor that becomes
// a libuh collision object. Its shape, the first given of: a prebuilt .ist file, a closed mesh
// file (packed by libuh, cached), or the static mesh (LOD 0 render data through the actor's scale;
// cooked builds need the mesh's "Allow CPU Access"; a Nanite mesh gives its fallback mesh, so give
// such a mesh an .ist or a mesh file). It registers with the HapticManager in BeginPlay; while the
// session runs its pose follows the actor (bFollowActor).
#pragma once

#include "CoreMinimal.h"
#include "Engine/StaticMeshActor.h"

#include "ColletteStaticMeshActor.generated.h"

class AHapticManager;
struct FUhObjectSpec;

UCLASS()
class UNREALHAPTICSCOLLETTE_API AColletteStaticMeshActor : public AStaticMeshActor
{
	GENERATED_BODY()

public:
	AColletteStaticMeshActor();

	/** Unset: the level's first HapticManager. */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Collette") TObjectPtr<AHapticManager> HapticManager;
	/** A prebuilt .ist file (uh pack) instead of the static mesh, relative to the project folder. */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Collette", meta = (FilePathFilter = "Inner Sphere Tree (*.ist)|*.ist", RelativeToGameDir))
	FFilePath IstFile;
	/** A closed mesh file libuh packs (cached) instead of the static mesh, relative to the project folder. */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Collette", meta = (FilePathFilter = "Mesh (*.obj;*.stl;*.ply;*.off)|*.obj;*.stl;*.ply;*.off", RelativeToGameDir))
	FFilePath MeshFile;
	/** The mesh file's length unit. */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Collette", meta = (ClampMin = "0.000001", Units = "m"))
	double MeshMetersPerUnit = 0.01;
	/** Leaf spheres when packing the static mesh or the mesh file. */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Collette", meta = (ClampMin = "100", ClampMax = "1000000", UIMax = "100000"))
	int64 Spheres = 10000;
	/** Collides with the tool (pushes back, reports contacts); off: the tool passes through it
	 *  unless a ColletteVolume watches it. */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Collette") bool bWatch = true;
	/** Send the actor's pose while the session runs (the object moves in the haptic scene). */
	UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Collette") bool bFollowActor = true;

	/** The object's name in libuh: the actor's name (unique in its level). */
	FString ObjectName() const { return GetName(); }

protected:
	virtual void BeginPlay() override;
	virtual void Tick(float DeltaSeconds) override;

private:
	bool ReadStaticMesh(FUhObjectSpec& Spec) const;

	FTransform SentTransform;
};
