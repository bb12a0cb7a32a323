// Polls a call every `ms` while the page is visible; the newest answer or error.
import { useEffect, useState } from 'preact/hooks';

export function usePoll(call, ms, deps = []) {
  const [state, setState] = useState({ data: null, error: null, loading: true });
  useEffect(() => {
    let stopped = false;
    let timer = null;
    async function tick() {
      clearTimeout(timer);
      if (stopped) return;
      if (!document.hidden) {
        try {
          const data = await call();
          if (!stopped) setState({ data, error: null, loading: false });
        } catch (error) {
          if (!stopped) setState((s) => ({ data: s.data, error, loading: false }));
        }
      }
      if (!stopped && ms) timer = setTimeout(tick, ms);
    }
    const onVis = () => { if (!document.hidden) tick(); };
    document.addEventListener('visibilitychange', onVis);
    tick();
    return () => { stopped = true; clearTimeout(timer); document.removeEventListener('visibilitychange', onVis); };
  }, deps);
  return state;
}
