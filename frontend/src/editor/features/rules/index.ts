import RulesModule from "diagram-js/lib/features/rules";

import ConnectMode from "../constraints/ConnectMode";
import LaneModule from "../lanes";
import PatternRules from "./PatternRules";
import RefusalHint from "./RefusalHint";
import Refusals from "./Refusals";

export default {
  __depends__: [RulesModule, LaneModule],
  __init__: ["patternRules", "refusalHint"],
  refusals: ["type", Refusals],
  refusalHint: ["type", RefusalHint],
  connectMode: ["type", ConnectMode],
  patternRules: ["type", PatternRules],
};
