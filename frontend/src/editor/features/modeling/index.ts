/** Modeling: diagram-js' command handlers and the pattern's own (data, ids, lanes). */

import ModelingModule from "diagram-js/lib/features/modeling";

import ConnectionCropping from "./ConnectionCropping";
import PatternModeling from "./PatternModeling";

export default {
  __depends__: [ModelingModule],
  __init__: ["connectionCropping"],
  modeling: ["type", PatternModeling],
  connectionCropping: ["type", ConnectionCropping],
};
