import PaletteModule from "diagram-js/lib/features/palette";
import CreateModule from "diagram-js/lib/features/create";
import HandToolModule from "diagram-js/lib/features/hand-tool";
import LassoToolModule from "diagram-js/lib/features/lasso-tool";
import GlobalConnectModule from "diagram-js/lib/features/global-connect";

import PaletteProvider from "./PaletteProvider";

export default {
  __depends__: [PaletteModule, CreateModule, HandToolModule, LassoToolModule, GlobalConnectModule],
  __init__: ["paletteProvider"],
  paletteProvider: ["type", PaletteProvider],
};
