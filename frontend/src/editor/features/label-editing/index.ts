import LabelEditing from "./LabelEditing";

export default {
  __init__: ["labelEditing"],
  labelEditing: ["type", LabelEditing],
};
