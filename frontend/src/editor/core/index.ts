/** The core: what pattern elements are, how they look, and the document ↔ canvas mapping. */

import CroppingConnectionDocking from "diagram-js/lib/layout/CroppingConnectionDocking";

import PatternElementFactory from "./PatternElementFactory";
import PatternImporter from "./PatternImporter";
import PatternRenderer from "./PatternRenderer";

export default {
  __init__: ["patternRenderer"],
  elementFactory: ["type", PatternElementFactory],
  patternRenderer: ["type", PatternRenderer],
  patternImporter: ["type", PatternImporter],
  connectionDocking: ["type", CroppingConnectionDocking],
};
