import CancelHighlight from "./CancelHighlight";

export default {
  __init__: ["cancelHighlight"],
  cancelHighlight: ["type", CancelHighlight],
};
