import LayoutModule from "../layout";
import PredictionModule from "../prediction";
import TokenGameModule from "../token-game";
import PatternFiles from "./PatternFiles";
import Toolbar from "./Toolbar";

export default {
  __depends__: [LayoutModule, TokenGameModule, PredictionModule],
  __init__: ["patternFiles", "toolbar"],
  patternFiles: ["type", PatternFiles],
  toolbar: ["type", Toolbar],
};
