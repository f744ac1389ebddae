#include "UnrealHapticsDemo.h"

#include "BridgingController.h"
#include "ColletteStaticMeshActor.h"
#include "Components/StaticMeshComponent.h"
#include "DrawDebugHelpers.h"
#include "Engine/Engine.h"
#include "Engine/StaticMesh.h"
#include "Engine/StaticMeshActor.h"
#include "Engine/World.h"
#include "ForceController.h"
#include "HapticManager.h"
#include "Interfaces/IPluginManager.h"
#include "Misc/FileHelper.h"
#include "Misc/Paths.h"
#include "UObject/ConstructorHelpers.h"
#include "UhConvert.h"
#include "UnrealHapticsLog.h"

namespace
{
	// libuh's default scene: the bunny's mesh file (staged by stage-libuh.sh), its unit and pose
	const TCHAR* const BunnyFile = TEXT("Source/ThirdParty/UhLibrary/data/bunny_npm_3674.obj");
	constexpr double BunnyMetersPerUnit = 0.01;
	constexpr double BunnyOrientation[4] = {0.70710678, 0.70710678, 0.0, 0.0};  // (w, x, y, z), libuh's frame
}

AUnrealHapticsDemo::AUnrealHapticsDemo()
{
	static ConstructorHelpers::FObjectFinder<UStaticMesh> Sphere(TEXT("/Engine/BasicShapes/Sphere.Sphere"));
	StylusMesh = Sphere.Object;
	RootComponent = CreateDefaultSubobject<USceneComponent>(TEXT("Root"));
}

// Spawned deferred: the properties are set before the actor's BeginPlay registers it.
template <typename T>
T* AUnrealHapticsDemo::SpawnConfigured(const FTransform& Transform, TFunctionRef<void(T&)> Configure)
{
	T* Actor = GetWorld()->SpawnActorDeferred<T>(T::StaticClass(), Transform, this);
	if (Actor != nullptr)
	{
		Configure(*Actor);
		Actor->FinishSpawning(Transform);
	}
	return Actor;
}

void AUnrealHapticsDemo::BeginPlay()
{
	Super::BeginPlay();
	AHapticManager* Manager = AHapticManager::FindIn(GetWorld());
	if (Manager == nullptr)
	{
		Manager = SpawnConfigured<AHapticManager>(FTransform::Identity, [](AHapticManager& M) { M.bDrawDebug = true; });
	}
	if (Manager == nullptr || Manager->GetSessionState() != EUhSessionState::Idle)
	{
		UE_LOG(LogUnrealHaptics, Error, TEXT("%s: no HapticManager taking registrations: the demo spawns nothing"), *GetName());
		return;
	}
	SpawnBunny(*Manager);
	Stylus = SpawnConfigured<AStaticMeshActor>(FTransform(FRotator::ZeroRotator, FVector::ZeroVector, FVector(StylusScale)),
		[this](AStaticMeshActor& S)
		{
			S.GetStaticMeshComponent()->SetMobility(EComponentMobility::Movable);
			S.GetStaticMeshComponent()->SetStaticMesh(StylusMesh);
			S.GetStaticMeshComponent()->SetCollisionEnabled(ECollisionEnabled::NoCollision);
		});
	SpawnConfigured<ABridgingController>(FTransform::Identity, [this, Manager](ABridgingController& C)
		{
			C.HapticManager = Manager;
			C.ToolActor = Stylus;
		});
	AForceController* Force = SpawnConfigured<AForceController>(FTransform::Identity, [this, Manager](AForceController& C)
		{
			C.HapticManager = Manager;
			C.ToolActor = Stylus;  // no ForceComponent: the scene's tool and force law
		});
	AColletteVolume* Volume = SpawnConfigured<AColletteVolume>(FTransform::Identity, [this, Manager](AColletteVolume& V)
		{
			V.HapticManager = Manager;
			V.Tool = Stylus;
			if (AColletteStaticMeshActor* Object = Cast<AColletteStaticMeshActor>(Bunny))
			{
				V.WatchedObjects.Add(Object);
			}
		});
	if (bPrintOnScreen && Force != nullptr && Volume != nullptr)
	{
		Force->ForceOnHapticTick.AddDynamic(this, &AUnrealHapticsDemo::PrintForce);
		Volume->OnCollision.AddDynamic(this, &AUnrealHapticsDemo::PrintCollision);
	}
}

// The bunny as a level object (a ColletteStaticMeshActor from the mesh file, replacing the default
// scene's own); without the staged file the scene's bunny stays, felt but not drawn.
void AUnrealHapticsDemo::SpawnBunny(AHapticManager& Manager)
{
	const TSharedPtr<IPlugin> Plugin = IPluginManager::Get().FindPlugin(TEXT("UnrealHaptics"));
	const FString Path = Plugin.IsValid() ? FPaths::ConvertRelativePathToFull(FPaths::Combine(Plugin->GetBaseDir(), BunnyFile)) : FString();
	if (Path.IsEmpty() || !FPaths::FileExists(Path))
	{
		UE_LOG(LogUnrealHaptics, Warning, TEXT("%s: %s missing (run stage-libuh.sh): the scene's bunny is felt but not drawn"), *GetName(),
			*Path);
		return;
	}
	const FTransform Pose(UhConvert::ToUnrealOrientation(BunnyOrientation), FVector::ZeroVector);
	Bunny = SpawnConfigured<AColletteStaticMeshActor>(Pose, [&Path](AColletteStaticMeshActor& B)
		{
			B.MeshFile.FilePath = Path;
			B.MeshMetersPerUnit = BunnyMetersPerUnit;
			B.bFollowActor = false;
		});
	if (Bunny != nullptr)
	{
		Manager.SceneObjectsToRemove.AddUnique(TEXT("bunny"));
		DrawMeshFile(Path, Pose, BunnyMetersPerUnit);
	}
}

// The mesh file's vertices and faces ("v" and "f" lines of an OBJ), drawn once with persistent
// debug lines in the actor's frame: libuh's mirrored Y, mesh units to centimetres.
void AUnrealHapticsDemo::DrawMeshFile(const FString& Path, const FTransform& Transform, double MetersPerUnit) const
{
#if ENABLE_DRAW_DEBUG
	TArray<FString> Lines;
	if (!FFileHelper::LoadFileToStringArray(Lines, *Path))
	{
		return;
	}
	const double UnitsPerMeshUnit = MetersPerUnit / UhConvert::MetersPerUnrealUnit;
	TArray<FVector> Vertices;
	TArray<int32> Indices;
	for (const FString& Line : Lines)
	{
		TArray<FString> Fields;
		Line.ParseIntoArrayWS(Fields);
		if (Fields.Num() >= 4 && Fields[0] == TEXT("v"))
		{
			const FVector Mesh(FCString::Atod(*Fields[1]), -FCString::Atod(*Fields[2]), FCString::Atod(*Fields[3]));
			Vertices.Add(Transform.TransformPosition(Mesh * UnitsPerMeshUnit));
		}
		else if (Fields.Num() >= 4 && Fields[0] == TEXT("f"))
		{
			for (int32 I = 2; I + 1 < Fields.Num(); ++I)  // a polygon as a fan of triangles
			{
				Indices.Append({FCString::Atoi(*Fields[1]) - 1, FCString::Atoi(*Fields[I]) - 1, FCString::Atoi(*Fields[I + 1]) - 1});
			}
		}
	}
	DrawDebugMesh(GetWorld(), Vertices, Indices, FColor(200, 190, 170), true);
#endif
}

void AUnrealHapticsDemo::PrintForce(FVector Force, FVector /*Torque*/)
{
	if (GEngine != nullptr)
	{
		GEngine->AddOnScreenDebugMessage(static_cast<uint64>(GetUniqueID()), 0.0f, FColor::Yellow,
			FString::Printf(TEXT("UnrealHaptics: force %.2f N"), Force.Size()));
	}
}

void AUnrealHapticsDemo::PrintCollision(AActor* A, AActor* /*B*/, const FUhCollisionData& Data)
{
	if (GEngine != nullptr && Data.Event != EUhCollisionEvent::Contact)
	{
		GEngine->AddOnScreenDebugMessage(-1, 3.0f, FColor::Cyan,
			FString::Printf(TEXT("UnrealHaptics: contact with %s %s (%d sphere pairs)"), *GetNameSafe(A),
				Data.Event == EUhCollisionEvent::Begin ? TEXT("begins") : TEXT("ends"), Data.Pairs));
	}
}
