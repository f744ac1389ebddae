#include "Framework/Notifications/NotificationManager.h"
#include "HapticManager.h"
#include "Modules/ModuleManager.h"
#include "Widgets/Notifications/SNotificationList.h"

#define LOCTEXT_NAMESPACE "UnrealHapticsEditor"

// One notification while any HapticManager builds its session (game thread: the manager's
// packing events come from its Tick, EndPlay and BeginDestroy).
class FUnrealHapticsEditorModule : public IModuleInterface
{
public:
	virtual void StartupModule() override
	{
		Started = AHapticManager::OnPackingStarted.AddRaw(this, &FUnrealHapticsEditorModule::PackingStarted);
		Finished = AHapticManager::OnPackingFinished.AddRaw(this, &FUnrealHapticsEditorModule::PackingFinished);
	}

	virtual void ShutdownModule() override
	{
		AHapticManager::OnPackingStarted.Remove(Started);
		AHapticManager::OnPackingFinished.Remove(Finished);
		Packing = 0;
		Close();
	}

private:
	void PackingStarted()
	{
		if (Packing++ > 0)
		{
			return;
		}
		FNotificationInfo Info(LOCTEXT("Packing", "UnrealHaptics: packing the haptic meshes (cached in Saved/UnrealHaptics for the next Play)"));
		Info.bFireAndForget = false;
		Info.bUseThrobber = true;
		Info.ExpireDuration = 1.0f;
		Notification = FSlateNotificationManager::Get().AddNotification(Info);
		if (Notification.IsValid())
		{
			Notification->SetCompletionState(SNotificationItem::CS_Pending);
		}
	}

	void PackingFinished()
	{
		if (Packing > 0 && --Packing == 0)
		{
			Close();
		}
	}

	void Close()
	{
		if (Notification.IsValid())
		{
			Notification->SetCompletionState(SNotificationItem::CS_Success);
			Notification->ExpireAndFadeout();
			Notification.Reset();
		}
	}

	FDelegateHandle Started;
	FDelegateHandle Finished;
	int32 Packing = 0;
	TSharedPtr<SNotificationItem> Notification;
};

#undef LOCTEXT_NAMESPACE

IMPLEMENT_MODULE(FUnrealHapticsEditorModule, UnrealHapticsEditor)
