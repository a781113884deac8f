import LayoutModule from "../layout";
import TokenGameModule from "../token-game";
import PatternFiles from "./PatternFiles";
import Toolbar from "./Toolbar";

export default {
  __depends__: [LayoutModule, TokenGameModule],
  __init__: ["patternFiles", "toolbar"],
  patternFiles: ["type", PatternFiles],
  toolbar: ["type", Toolbar],
};
