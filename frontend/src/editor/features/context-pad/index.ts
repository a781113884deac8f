import AutoPlaceModule from "diagram-js/lib/features/auto-place";
import ConnectModule from "diagram-js/lib/features/connect";
import ContextPadModule from "diagram-js/lib/features/context-pad";

import Append from "./Append";
import ContextPadProvider from "./ContextPadProvider";

export default {
  __depends__: [ContextPadModule, ConnectModule, AutoPlaceModule],
  __init__: ["contextPadProvider"],
  append: ["type", Append],
  contextPadProvider: ["type", ContextPadProvider],
};
