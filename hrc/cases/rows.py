"""Plain SQL for the rows the hot path reads and writes: a case, its work items, its jobs.

A completion, a lease and a finish each run a handful of statements, and on this stack the
ORM spends more of a worker's CPU building each one than PostgreSQL spends running it. These
helpers write the same SQL the ORM would, from the models' own fields (their columns, their
conversions to and from the database, auto_now_add), with each statement's text built once
per process. The SQL is portable: on SQLite a row lock is left out, as the ORM leaves it out.
Everything else keeps using the ORM.
"""

from __future__ import annotations

import datetime as dt
import functools
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

from django.db import connection
from django.db.models import Field, Model, QuerySet

M = TypeVar("M", bound=Model)
Converter = Callable[[Any, Any, Any], Any]
# Stand-ins for a compiled query's values (see Compiled): none is a value a query meets.
_FIRST_STAND_IN = -7_100_000_000
_STAND_IN_EPOCH = dt.datetime(1901, 1, 1, tzinfo=dt.UTC)
_STAND_IN_SPACING = dt.timedelta(days=3650)  # a value may be offset by less than half of this


def fetch(model: type[M], where: str, params: Sequence[Any], *, lock: str = "") -> list[M]:
    """The rows of `model` matching `where` (SQL over its table's columns, %s parameters), as
    instances. `lock` is a row-locking clause ("FOR NO KEY UPDATE", "… SKIP LOCKED"), left out
    where the database has none."""
    return [instance for instance, _ in fetch_with(model, where, params, (), lock=lock)]


def fetch_one(model: type[M], where: str, params: Sequence[Any], *, lock: str = "") -> M | None:
    found = fetch(model, where, params, lock=lock)
    return found[0] if found else None


def fetch_with(
    model: type[M], where: str, params: Sequence[Any], extra: Sequence[str], *, lock: str = ""
) -> list[tuple[M, tuple[Any, ...]]]:
    """fetch, each instance with the values of the `extra` SQL expressions read along (their
    parameters come first in `params`)."""
    columns, _ = _columns(model, connection.vendor)
    more = "".join(f", {expression}" for expression in extra)
    suffix = f" {lock}" if lock and connection.features.has_select_for_update else ""
    sql = f"SELECT {columns}{more} FROM {table(model)} WHERE {where}{suffix}"
    width = len(model._meta.concrete_fields)
    with connection.cursor() as cursor:
        cursor.execute(sql, list(params))
        return [(_instance(model, row[:width]), tuple(row[width:])) for row in cursor.fetchall()]


def fetch_each(
    models: Sequence[type[Model]], where: str, params: Sequence[Any], *, lock: str = ""
) -> tuple[Model, ...] | None:
    """One row of each of `models`, read in one statement: `where` joins their tables and
    narrows each to one row; None when there is no such row. `lock` locks every row, in the
    order of `models` (PostgreSQL takes a statement's row locks table by table, in FROM
    order), and then reads each as its newest committed version, even after waiting."""
    found = fetch_each_with(models, where, params, (), lock=lock)
    return None if found is None else found[0]


def fetch_each_with(
    models: Sequence[type[Model]],
    where: str,
    params: Sequence[Any],
    extra: Sequence[str],
    *,
    lock: str = "",
) -> tuple[tuple[Model, ...], tuple[Any, ...]] | None:
    """fetch_each, with the values of the `extra` SQL expressions read along (their parameters
    come first in `params`)."""
    selected = ", ".join(_columns(model, connection.vendor)[0] for model in models)
    more = "".join(f", {expression}" for expression in extra)
    suffix = f" {lock}" if lock and connection.features.has_select_for_update else ""
    tables = ", ".join(table(model) for model in models)
    sql = f"SELECT {selected}{more} FROM {tables} WHERE {where}{suffix}"
    with connection.cursor() as cursor:
        cursor.execute(sql, list(params))
        row = cursor.fetchone()
    if row is None:
        return None
    found, start = [], 0
    for model in models:
        width = len(model._meta.concrete_fields)
        found.append(_instance(model, row[start : start + width]))
        start += width
    return tuple(found), tuple(row[start:])


def update(instance: Model, fields: Sequence[str]) -> int:
    """UPDATE of the instance's row: these fields, by its primary key; the rows changed."""
    model = type(instance)
    sql, chosen = _update_sql(model, tuple(fields))
    with connection.cursor() as cursor:
        cursor.execute(sql, [*_values(instance, chosen, adding=False), instance.pk])
        return int(cursor.rowcount)


def update_where(
    model: type[Model], values: dict[str, Any], where: str, params: Sequence[Any]
) -> int:
    """UPDATE of `model`'s rows matching `where` (SQL over its columns, %s parameters): these
    fields to these values; the rows changed."""
    sql, chosen = _update_sql(model, tuple(values), where)
    prepared = [field.get_db_prep_save(values[field.name], connection) for field in chosen]
    with connection.cursor() as cursor:
        cursor.execute(sql, [*prepared, *params])
        return int(cursor.rowcount)


def save_with(
    instance: Model,
    fields: Sequence[str],
    *,
    inserts: Sequence[Model] = (),
    updates: Sequence[tuple[Model, Sequence[str]]] = (),
) -> None:
    """UPDATE of the instance's `fields`, with the INSERT of new rows of one model (`inserts`,
    whose primary keys are not read back) and the UPDATEs of other rows (`updates`), in one
    statement: a WITH of data-modifying statements (PostgreSQL), else one statement each."""
    if connection.vendor != "postgresql":
        for row, changed in updates:
            update(row, changed)
        if inserts:
            manager: Any = type(inserts[0])._default_manager
            manager.bulk_create(inserts)
        update(instance, fields)
        return
    parts: list[str] = []
    params: list[Any] = []
    if inserts:
        head, columns = _insert_head(type(inserts[0]))
        values = f"({', '.join(['%s'] * len(columns))})"
        parts.append(f"inserted AS ({head} VALUES {', '.join([values] * len(inserts))})")
        for new in inserts:
            params += _values(new, columns, adding=True)
    for index, (other, changed) in enumerate(updates):
        sql, chosen = _update_sql(type(other), tuple(changed))
        parts.append(f"updated_{index} AS ({sql})")
        params += [*_values(other, chosen, adding=False), other.pk]
    sql, chosen = _update_sql(type(instance), tuple(fields))
    params += _values(instance, chosen, adding=False)
    with connection.cursor() as cursor:
        cursor.execute(f"WITH {', '.join(parts)} {sql}" if parts else sql, [*params, instance.pk])
    _saved(*inserts)


def insert(instance: Model) -> None:
    """INSERT of a new instance, as Model.save() would (defaults, auto_now_add); sets its pk."""
    sql, fields = _insert_returning_key(type(instance))
    with connection.cursor() as cursor:
        cursor.execute(sql, _values(instance, fields, adding=True))
        instance.pk = cursor.fetchone()[0]
    _saved(instance)


def insert_with(instance: Model, child: Model, link: str) -> None:
    """insert of a new instance and of a new `child` whose foreign key `link` points at it, in
    one statement (PostgreSQL: a WITH of data-modifying statements), else one each; sets both
    primary keys and the child's key."""
    if connection.vendor != "postgresql":
        insert(instance)
        setattr(child, link, instance)
        insert(child)
        return
    parent_sql, fields = _insert_returning_key(type(instance))
    child_head, child_fields = _insert_head(type(child))
    key = next(field for field in child_fields if field.name == link)
    quote = connection.ops.quote_name
    primary = quote(_column(type(instance)._meta.pk))
    child_primary = quote(_column(type(child)._meta.pk))
    selected = ", ".join(f"parent.{primary}" if field is key else "%s" for field in child_fields)
    sql = (
        f"WITH parent AS ({parent_sql}) "
        f"{child_head} SELECT {selected} FROM parent RETURNING {child_primary}, {quote(_column(key))}"
    )
    child_values = [field for field in child_fields if field is not key]
    params = [*_values(instance, fields, adding=True), *_values(child, child_values, adding=True)]
    with connection.cursor() as cursor:
        cursor.execute(sql, params)
        child.pk, instance.pk = cursor.fetchone()
    setattr(child, link, instance)
    _saved(instance, child)


def _saved(*instances: Model) -> None:
    """Marks new instances as rows of this database, as Model.save() does once it inserted them."""
    for instance in instances:
        instance._state.adding, instance._state.db = False, connection.alias


def _values(instance: Model, fields: Sequence[Field[Any, Any]], *, adding: bool) -> list[Any]:
    """The instance's values of `fields` as the database takes them, as Model.save() sends them."""
    return [
        field.get_db_prep_save(field.pre_save(instance, adding), connection) for field in fields
    ]


def table(model: type[Model]) -> str:
    """The model's table, quoted for SQL."""
    return connection.ops.quote_name(model._meta.db_table)


def _instance(model: type[M], row: Sequence[Any]) -> M:
    _, converters = _columns(model, connection.vendor)
    values = list(row)
    for index, convert in converters:
        values[index] = convert(values[index])
    return model.from_db(connection.alias, _attnames(model), values)


@functools.cache
def _attnames(model: type[Model]) -> tuple[str, ...]:
    return tuple(field.attname for field in model._meta.concrete_fields)


@functools.cache
def _columns(model: type[Model], vendor: str) -> tuple[str, list[tuple[int, Callable[[Any], Any]]]]:
    """The SELECT list of the model's concrete fields in from_db's order, and the conversions
    the ORM applies to each value read on that database (JSON decoded; SQLite's dates)."""
    quote, name = connection.ops.quote_name, table(model)
    fields = model._meta.concrete_fields
    converters: list[tuple[int, Callable[[Any], Any]]] = []
    for index, field in enumerate(fields):
        column = field.get_col(model._meta.db_table)
        found: list[Converter] = [
            *connection.ops.get_db_converters(column),
            *column.get_db_converters(connection),
        ]
        if found:
            converters.append((index, _chain(found, column)))
    selected = ", ".join(f"{name}.{quote(_column(field))}" for field in fields)
    return selected, converters


def _chain(converters: list[Converter], column: Any) -> Callable[[Any], Any]:
    def convert(value: Any) -> Any:
        for converter in converters:
            value = converter(value, column, connection)
        return value

    return convert


@functools.cache
def _update_sql(
    model: type[Model], names: tuple[str, ...], where: str = ""
) -> tuple[str, list[Field[Any, Any]]]:
    """The UPDATE of the fields `names` of the rows matching `where` (by default: the primary
    key), and those fields, in the order of their parameters."""
    quote = connection.ops.quote_name
    chosen = [field for field in model._meta.concrete_fields if field.name in names]
    if len(chosen) != len(set(names)):
        raise ValueError(f"{model.__name__} has no field among some of {names}.")
    assignments = ", ".join(f"{quote(_column(field))} = %s" for field in chosen)
    where = where or f"{quote(_column(model._meta.pk))} = %s"
    return f"UPDATE {table(model)} SET {assignments} WHERE {where}", chosen


@functools.cache
def _insert_returning_key(model: type[Model]) -> tuple[str, list[Field[Any, Any]]]:
    """The INSERT of one row of `model`, its primary key returned, and the fields it takes."""
    head, fields = _insert_head(model)
    primary = connection.ops.quote_name(_column(model._meta.pk))
    return f"{head} VALUES ({', '.join(['%s'] * len(fields))}) RETURNING {primary}", fields


@functools.cache
def _insert_head(model: type[Model]) -> tuple[str, list[Field[Any, Any]]]:
    """The INSERT's head (its table and columns: the model's fields but the primary key), and
    the fields."""
    quote = connection.ops.quote_name
    fields = [field for field in model._meta.concrete_fields if not field.primary_key]
    head = f"INSERT INTO {table(model)} ({', '.join(quote(_column(field)) for field in fields)})"
    return head, fields


def _column(field: Field[Any, Any]) -> str:
    return field.column or field.attname


class Compiled:
    """An ORM query compiled to SQL once per process (on PostgreSQL), then run with new values:
    the rule stays written once, with the ORM, and the hot path pays only for running it.

    `build(**values)` returns the query (a values_list). It is compiled with a stand-in for
    each value (an int, or a datetime: a value derived from one by an offset, such as "now
    less five minutes", keeps its offset); each parameter of the SQL that is a stand-in is
    then replaced by the value given. A query whose SQL depends on the values themselves (a
    list whose length varies) cannot be compiled so.
    """

    def __init__(self, build: Callable[..., QuerySet[Any, Any]]) -> None:
        self.build = build
        self._sql: dict[str, tuple[str, list[Any], dict[str, Any]]] = {}

    def __call__(self, **values: int | dt.datetime) -> list[tuple[Any, ...]]:
        if connection.vendor != "postgresql":
            # Elsewhere (SQLite) parameters are adapted as text at compile time: the ORM runs it.
            return [tuple(row) for row in self.build(**values)]
        sql, template, stand_ins = self._compiled(values)
        params = [_put_back(param, stand_ins, values) for param in template]
        with connection.cursor() as cursor:
            cursor.execute(sql, params)
            return [tuple(row) for row in cursor.fetchall()]

    def _compiled(self, values: dict[str, Any]) -> tuple[str, list[Any], dict[str, Any]]:
        key = connection.alias
        if key not in self._sql:
            stand_ins = {
                name: _stand_in(index, value)
                for index, (name, value) in enumerate(sorted(values.items()))
            }
            sql, params = self.build(**stand_ins).query.sql_with_params()
            self._sql[key] = (sql, list(params), stand_ins)
        return self._sql[key]


def _stand_in(index: int, value: object) -> int | dt.datetime:
    if isinstance(value, dt.datetime):
        return _STAND_IN_EPOCH + index * _STAND_IN_SPACING
    if isinstance(value, int) and not isinstance(value, bool):
        return _FIRST_STAND_IN - index
    raise TypeError(f"A compiled query takes ints and datetimes, not {value!r}.")


def _put_back(param: Any, stand_ins: dict[str, Any], values: dict[str, Any]) -> Any:
    for name, stand_in in stand_ins.items():
        if isinstance(stand_in, dt.datetime) and isinstance(param, dt.datetime):
            offset = param - stand_in
            if abs(offset) < _STAND_IN_SPACING / 2:
                return values[name] + offset
        elif type(param) is int and param == stand_in:
            return values[name]
    return param
