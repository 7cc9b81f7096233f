// The n a module serves: within N_RANGE, or the exported n where it is baked in.
function checkedN(n) {
  const fits = N_RANGE === null ? n === EXPORTED_N : n >= N_RANGE[0] && n <= N_RANGE[1];
  if (typeof n !== "number" || !fits) {
    const valid = N_RANGE === null ? `${EXPORTED_N} (its constants are fitted for it)` : `in [${N_RANGE[0]}, ${N_RANGE[1]}]`;
    throw new RangeError(`specula ${LOBE}: n = ${n} is not served by this export; n must be ${valid}`);
  }
  return n;
}
