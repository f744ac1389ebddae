// An emulated headset with two controllers (IWER, the Immersive Web Emulation Runtime) installed as
// the page's WebXR runtime before the museum page starts: for the VR test only, never shipped.
import { XRDevice, metaQuest3 } from 'iwer';

const device = new XRDevice(metaQuest3, { stereoEnabled: true });
device.installRuntime({ forceInstall: true });
// what the test drives (the headset and the controllers) and reads: every pulse the page sends to
// a controller's haptic actuator
window.uhXRDevice = device;
window.uhXRPulses = [];
for (const hand of ['left', 'right']) {
  const actuator = device.controllers[hand].inputSource.gamepad.hapticActuators[0];
  const pulse = actuator.pulse.bind(actuator);
  actuator.pulse = (value, duration) => {
    window.uhXRPulses.push({ hand, value, duration });
    return pulse(value, duration);
  };
}
