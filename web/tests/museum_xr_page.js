// The museum page on an emulated headset (the VR test's page): the emulation first, then the page.
import './museum_xr_emulation.js';
import '../src/museum.js';
