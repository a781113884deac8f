import AutoLayout from "./AutoLayout";

export default {
  __init__: ["autoLayout"],
  autoLayout: ["type", AutoLayout],
};
