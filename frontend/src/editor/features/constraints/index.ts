import ConstraintHighlight from "./ConstraintHighlight";

export default {
  __init__: ["constraintHighlight"],
  constraintHighlight: ["type", ConstraintHighlight],
};
