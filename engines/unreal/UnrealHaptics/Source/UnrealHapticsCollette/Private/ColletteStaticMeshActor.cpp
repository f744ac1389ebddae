#include "ColletteStaticMeshActor.h"

#include "Components/StaticMeshComponent.h"
#include "Engine/StaticMesh.h"
#include "HAL/PlatformProperties.h"
#include "HapticManager.h"
#include "Rendering/PositionVertexBuffer.h"
#include "StaticMeshResources.h"
#include "UhConvert.h"
#include "UhPaths.h"
#include "UnrealHapticsLog.h"

AColletteStaticMeshActor::AColletteStaticMeshActor()
{
	PrimaryActorTick.bCanEverTick = true;
}

void AColletteStaticMeshActor::BeginPlay()
{
	Super::BeginPlay();
	if (AHapticManager::Resolve(HapticManager, *this, TEXT("not a collision object")) == nullptr)
	{
		return;
	}
	FUhObjectSpec Spec;
	Spec.Name = ObjectName();
	Spec.Spheres = Spheres;
	Spec.bWatch = bWatch;
	const FTransform Pose = GetActorTransform();
	UhConvert::Position(Pose.GetLocation(), Spec.Position);
	UhConvert::Orientation(Pose.GetRotation(), Spec.Orientation);
	if (!IstFile.FilePath.IsEmpty() || !MeshFile.FilePath.IsEmpty())
	{
		Spec.IstPath = UhPaths::ResolveProjectFile(IstFile.FilePath);
		Spec.MeshPath = Spec.IstPath.IsEmpty() ? UhPaths::ResolveProjectFile(MeshFile.FilePath) : FString();
		Spec.MeshMetersPerUnit = MeshMetersPerUnit;
		if (!Pose.GetScale3D().Equals(FVector::OneVector))
		{
			UE_LOG(LogUnrealHaptics, Warning, TEXT("%s: the actor's scale does not apply to an .ist or mesh file"), *GetName());
		}
	}
	else if (!ReadStaticMesh(Spec))
	{
		return;
	}
	SentTransform = Pose;
	HapticManager->RegisterObject(MoveTemp(Spec));
}

// LOD 0 of the render data in the actor's frame with its scale (metres, libuh's mirrored Y); split
// vertices (UV seams, hard edges) are welded by libuh. A mesh whose vertices the CPU cannot read
// is refused with the reason instead of read through a freed buffer.
bool AColletteStaticMeshActor::ReadStaticMesh(FUhObjectSpec& Spec) const
{
	const UStaticMesh* Mesh = GetStaticMeshComponent()->GetStaticMesh();
	const FStaticMeshRenderData* Render = Mesh != nullptr ? Mesh->GetRenderData() : nullptr;
	if (Render == nullptr || Render->LODResources.Num() == 0)
	{
		UE_LOG(LogUnrealHaptics, Error, TEXT("%s: no static mesh render data (set a mesh, a mesh file or an .ist file)"), *GetName());
		return false;
	}
	if (FPlatformProperties::RequiresCookedData() && !Mesh->bAllowCPUAccess)
	{
		UE_LOG(LogUnrealHaptics, Error, TEXT("%s: the static mesh %s needs \"Allow CPU Access\" in a cooked build (or give an .ist or mesh file)"),
			*GetName(), *Mesh->GetName());
		return false;
	}
	if (Mesh->IsNaniteEnabled())
	{
		UE_LOG(LogUnrealHaptics, Warning, TEXT("%s: %s is a Nanite mesh: its coarse fallback mesh is packed (give an .ist or a mesh file for the full detail)"),
			*GetName(), *Mesh->GetName());
	}
	const FStaticMeshLODResources& Lod = Render->LODResources[0];
	const FPositionVertexBuffer& Positions = Lod.VertexBuffers.PositionVertexBuffer;
	const FIndexArrayView Indices = Lod.IndexBuffer.GetArrayView();
	if (Positions.GetNumVertices() == 0 || Indices.Num() == 0)
	{
		UE_LOG(LogUnrealHaptics, Error, TEXT("%s: the static mesh %s has no vertices or indices the CPU can read"), *GetName(), *Mesh->GetName());
		return false;
	}
	const FVector Scale = GetActorTransform().GetScale3D();
	Spec.Vertices.Reserve(Positions.GetNumVertices() * 3);
	for (uint32 I = 0; I < Positions.GetNumVertices(); ++I)
	{
		double P[3];
		UhConvert::Position(FVector(Positions.VertexPosition(I)) * Scale, P);
		Spec.Vertices.Append(P, 3);
	}
	Spec.Indices.Reserve(Indices.Num());
	for (int32 I = 0; I < Indices.Num(); ++I)
	{
		Spec.Indices.Add(static_cast<int32>(Indices[I]));
	}
	return true;
}

void AColletteStaticMeshActor::Tick(float DeltaSeconds)
{
	Super::Tick(DeltaSeconds);
	if (bFollowActor && HapticManager != nullptr && HapticManager->IsRunning() && !GetActorTransform().Equals(SentTransform, 0.0))
	{
		SentTransform = GetActorTransform();
		HapticManager->SetObjectPose(ObjectName(), SentTransform);
	}
}
