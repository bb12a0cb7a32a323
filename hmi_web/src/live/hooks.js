// Preact hooks over the live hub.
import { useEffect, useState } from 'preact/hooks';
import { connectionState, onConnection, subscribe } from './hub.js';
import { link } from '../api/link.js';

// Re-renders the component at most every `minMs` with the newest values of refs.
export function useLive(refs, minMs = 100) {
  const [tick, setTick] = useState(0);
  const key = refs.join(',');
  useEffect(() => {
    if (!refs.length) return undefined;
    let last = 0;
    let timer = null;
    const unsub = subscribe(refs, () => {
      const now = Date.now();
      if (now - last >= minMs) { last = now; setTick((t) => t + 1); } else if (!timer) {
        timer = setTimeout(() => { timer = null; last = Date.now(); setTick((t) => t + 1); }, minMs);
      }
    });
    return () => { unsub(); clearTimeout(timer); };
  }, [key]);
  return tick;
}

// Calls fn(tNs) on every update of refs, without re-rendering (plots).
export function useLiveCallback(refs, fn) {
  const key = refs.join(',');
  useEffect(() => (refs.length ? subscribe(refs, fn) : undefined), [key, fn]);
}

export function useConnection() {
  const [c, setC] = useState(connectionState());
  useEffect(() => onConnection(setC), []);
  return c;
}

// Whether the PLC answers the page's requests (api/link.js).
export function useLink() {
  const [c, setC] = useState(link.state());
  useEffect(() => link.onChange(setC), []);
  return c;
}
