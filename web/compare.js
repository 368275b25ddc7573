// compare.js - several cases' history series on one plot (a parametric
// study): the cases ticked in the list, one line each, for a series the
// first of them has (an energy term, a constraint force, a point's
// displacement).

import * as api from "./api.js";
import { Plot, historyChoices, historySeries } from "./plots.js";

const $ = id => document.getElementById(id);

export class Compare {
  constructor(checkedIds, statusOf, guarded) {
    this.checkedIds = checkedIds;
    this.statusOf = statusOf;
    this.guarded = guarded;
    this.plot = new Plot($("plot-compare"), "Comparison", "time (s)", "", { height: 360 });
    $("compare-series").addEventListener("change", () => this.refresh());
    $("compare-refresh").addEventListener("click", () => this.refresh());
  }

  async refresh() {
    if ($("tab-compare").hidden) return;
    const ids = this.checkedIds();
    const histories = [];
    for (const id of ids) {
      const h = await this.guarded(() => api.json("GET", `/cases/${id}/history`));
      if (h) histories.push({ id, h });
    }
    const menu = $("compare-series"), keep = menu.value;
    const choices = histories.length ? historyChoices(histories[0].h) : [];
    menu.textContent = "";
    for (const c of choices) menu.add(new Option(c.label, c.key));
    if (choices.some(c => c.key === keep)) menu.value = keep;
    const key = menu.value;
    if (!key) { this.plot.set([]); return; }
    const label = [...menu.options].find(o => o.value === key).text;
    this.plot.yLabel = label;
    this.plot.set(histories
      .filter(({ h }) => historyChoices(h).some(c => c.key === key))
      .map(({ id, h }) => historySeries(h, key, `${(this.statusOf(id) || {}).name || ""} ${id.slice(0, 6)}`)));
  }
}
