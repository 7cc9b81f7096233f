// The machine-code view: the chosen lobe's code beside pow's, as a GPU vendor's compiler
// writes it (/api/isa, `specula isa`), special-function instructions marked. Drawn by the
// page's update, so it follows the lobe, n and the GPU chosen here.
"use strict";

// A kernel's listing, each instruction tagged with its class; the special-function unit's
// marked, as `specula isa` marks them.
function isaListing(view) {
  const pre = document.createElement("pre");
  pre.className = "isa-code";
  pre.append(...view.listing.map(([cls, text]) => {
    const line = document.createElement("span");
    line.className = `isa-line isa-${cls}`;
    line.textContent = `${cls === "transcendental" ? "*" : " "} ${cls.padEnd(15)} ${text}\n`;
    return line;
  }));
  return pre;
}

// The counts side by side: what each kernel executes beyond one that only loads and stores.
function isaCounts(answer) {
  const table = document.createElement("table");
  const row = (cells, header = false) => {
    const tr = document.createElement("tr");
    tr.append(...cells.map((text) => Object.assign(document.createElement(header ? "th" : "td"), { textContent: text })));
    return tr;
  };
  table.append(row(["class", answer.lobe.lobe, "pow"], true));
  answer.lobe.counts.forEach(([cls, count], k) => table.append(row([cls, String(count), String(answer.pow.counts[k][1])])));
  table.append(row(["total", String(answer.lobe.total), String(answer.pow.total)]));
  if (answer.lobe.registers != null) table.append(row(["registers", String(answer.lobe.registers), String(answer.pow.registers)]));
  return table;
}

// Draws the answer for the lobe shown as `name` (the page's name for it).
function drawIsa(answer, name) {
  $("isa-lobe").textContent = name;
  $("isa-error").textContent = "";
  const rate = (x) => Number.isFinite(x) ? x.toFixed(3) : "unbounded";
  const summary = `${answer.gpu.name}, compiled by ${answer.lobe.compiler}: ${rate(answer.lobe.evals_per_clock)} evaluations per clock per ${answer.gpu.unit} (bound by ${answer.lobe.bound}) against pow's ${rate(answer.pow.evals_per_clock)}: ${answer.throughput_vs_pow.toFixed(2)}x pow's throughput.`;
  $("isa-summary").textContent = summary;
  $("isa-counts").replaceChildren(isaCounts(answer));
  const column = (view) => {
    const div = document.createElement("div");
    div.append(Object.assign(document.createElement("h3"), { textContent: `${view.lobe} (${view.listing.length} instructions)` }), isaListing(view));
    return div;
  };
  $("isa-code").replaceChildren(column(answer.lobe), column(answer.pow));
}

// The view's request for the lobe `name` (API spelling) at `n` on the chosen GPU: the answer,
// or the refusal shown beside the GPU control (a compiler missing says how to install it).
async function updateIsa(apiName, shownName, n, signal) {
  const query = new URLSearchParams({ lobe: apiName, n, gpu: $("gpu").value });
  try {
    drawIsa(await getJson("/api/isa?" + query, signal, "/api/isa"), shownName);
    markFresh("isa");
  } catch (error) {
    if (error.name === "AbortError") throw error;
    // The code below is the last that compiled: the view stays marked out of date.
    $("isa-error").textContent = error.refusal ?? error.message;
  }
}
