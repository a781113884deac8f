import SelectionModule from "diagram-js/lib/features/selection";

import PropertiesPanel from "./PropertiesPanel";

export default {
  __depends__: [SelectionModule],
  __init__: ["propertiesPanel"],
  propertiesPanel: ["type", PropertiesPanel],
};
