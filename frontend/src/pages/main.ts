// What every page may need and the Content-Security-Policy keeps out of the HTML: no
// inline handlers, so a form that asks before it posts says so in data-confirm and is
// answered here (templates/base.html loads this on every page).

document.addEventListener("submit", (event) => {
  const form = event.target;
  if (!(form instanceof HTMLFormElement) || form.dataset.confirm === undefined) return;
  if (!window.confirm(form.dataset.confirm)) event.preventDefault();
});
