// Files named in the editor (scene, .ist, mesh) are stored relative to the project folder (the
// properties' RelativeToGameDir); they resolve against FPaths::ProjectDir(), never against the
// working directory or Binaries/, so the same path works in the editor and in a packaged game
// (which stages them with DirectoriesToAlwaysStageAsNonUFS: see the README).
#pragma once

#include "CoreMinimal.h"
#include "Misc/Paths.h"

namespace UhPaths
{
	/** An absolute path for a path given in the editor; empty stays empty. */
	inline FString ResolveProjectFile(const FString& Path)
	{
		if (Path.IsEmpty())
		{
			return Path;
		}
		const FString Absolute = FPaths::IsRelative(Path) ? FPaths::Combine(FPaths::ProjectDir(), Path) : Path;
		return FPaths::ConvertRelativePathToFull(Absolute);
	}
}
