import CopyPasteModule from "diagram-js/lib/features/copy-paste";

import CopyBehavior from "./CopyBehavior";

export default {
  __depends__: [CopyPasteModule],
  __init__: ["copyBehavior"],
  copyBehavior: ["type", CopyBehavior],
};
