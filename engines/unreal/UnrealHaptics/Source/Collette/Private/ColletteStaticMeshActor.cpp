#include "ColletteStaticMeshActor.h"

#include "Components/StaticMeshComponent.h"
#include "Engine/StaticMesh.h"
#include "HapticManager.h"
#include "Rendering/StaticMeshVertexBuffer.h"
#include "StaticMeshResources.h"
#include "UhConvert.h"

DEFINE_LOG_CATEGORY_STATIC(LogCollette, Log, All);

AColletteStaticMeshActor::AColletteStaticMeshActor()
{
	PrimaryActorTick.bCanEverTick = true;
}

void AColletteStaticMeshActor::BeginPlay()
{
	Super::BeginPlay();
	if (HapticManager == nullptr)
	{
		HapticManager = AHapticManager::FindIn(GetWorld());
	}
	if (HapticManager == nullptr)
	{
		UE_LOG(LogCollette, Error, TEXT("%s: no HapticManager in the level"), *GetName());
		return;
	}
	FUhObjectSpec Spec;
	Spec.Name = ObjectName();
	Spec.Spheres = Spheres;
	Spec.bWatch = bWatch;
	Spec.Actor = this;
	const FTransform Pose = GetActorTransform();
	UhConvert::Position(Pose.GetLocation(), Spec.Position);
	UhConvert::Orientation(Pose.GetRotation(), Spec.Orientation);
	if (!IstFile.FilePath.IsEmpty())
	{
		Spec.IstPath = FPaths::ConvertRelativePathToFull(IstFile.FilePath);
	}
	else
	{
		const UStaticMesh* Mesh = GetStaticMeshComponent()->GetStaticMesh();
		const FStaticMeshRenderData* Render = Mesh != nullptr ? Mesh->GetRenderData() : nullptr;
		if (Render == nullptr || Render->LODResources.Num() == 0)
		{
			UE_LOG(LogCollette, Error, TEXT("%s: no static mesh render data (set a mesh, or an .ist file)"), *GetName());
			return;
		}
		// LOD 0 in the actor's frame with its scale (metres, libuh's mirrored Y); split vertices
		// (UV seams, hard edges) are welded by libuh
		const FStaticMeshLODResources& Lod = Render->LODResources[0];
		const FPositionVertexBuffer& Positions = Lod.VertexBuffers.PositionVertexBuffer;
		const FVector Scale = Pose.GetScale3D();
		Spec.Vertices.Reserve(Positions.GetNumVertices() * 3);
		for (uint32 I = 0; I < Positions.GetNumVertices(); ++I)
		{
			double P[3];
			UhConvert::Position(FVector(Positions.VertexPosition(I)) * Scale, P);
			Spec.Vertices.Append(P, 3);
		}
		const FIndexArrayView Indices = Lod.IndexBuffer.GetArrayView();
		Spec.Indices.Reserve(Indices.Num());
		for (int32 I = 0; I < Indices.Num(); ++I)
		{
			Spec.Indices.Add(static_cast<int32>(Indices[I]));
		}
	}
	SentTransform = Pose;
	HapticManager->RegisterObject(MoveTemp(Spec));
}

void AColletteStaticMeshActor::Tick(float DeltaSeconds)
{
	Super::Tick(DeltaSeconds);
	if (bFollowActor && HapticManager != nullptr && HapticManager->IsRunning() &&
		!GetActorTransform().Equals(SentTransform, 0.0))
	{
		SentTransform = GetActorTransform();
		HapticManager->SetObjectPose(ObjectName(), SentTransform);
	}
}
