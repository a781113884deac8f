import SelectionModule from "diagram-js/lib/features/selection";

import PredictionMarkers from "./PredictionMarkers";
import PredictPanel from "./PredictPanel";

export default {
  __depends__: [SelectionModule],
  __init__: ["predictPanel"],
  predictionMarkers: ["type", PredictionMarkers],
  predictPanel: ["type", PredictPanel],
};
