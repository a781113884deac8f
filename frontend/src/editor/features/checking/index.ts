import OverlaysModule from "diagram-js/lib/features/overlays";

import TokenGameModule from "../token-game";
import CheckPanel from "./CheckPanel";
import IssueOverlays from "./IssueOverlays";
import LiveChecker from "./LiveChecker";

export default {
  __depends__: [OverlaysModule, TokenGameModule],
  __init__: ["liveChecker", "issueOverlays", "checkPanel"],
  liveChecker: ["type", LiveChecker],
  issueOverlays: ["type", IssueOverlays],
  checkPanel: ["type", CheckPanel],
};
