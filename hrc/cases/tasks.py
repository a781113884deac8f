"""Celery tasks of the cases app: thin, idempotent, ids only; the logic is in jobs.py.

A task may run twice (a redelivery, the sweeper ringing again): each one
re-reads the rows and does nothing when there is nothing to do. Each is
registered under its dispatch.Task name, which is how the cases app sends it.
"""

from typing import Any

from celery import shared_task

from hrc.cases import device_jobs, interruptions, jobs, timers
from hrc.cases.dispatch import Task
from hrc.cases.messages import deliver_sent_message, purge_expired_messages, sweep_sent_messages


@shared_task(name=Task.RUN_JOB.value, ignore_result=True)
def run_job(job_id: int) -> None:
    """Rings the doorbell of `job_id`'s queue, a cobot's or a device's: runs its next job that may
    run (not necessarily `job_id`)."""
    if device_jobs.is_device_job(job_id):
        device_jobs.run_next_device_job(job_id)
    else:
        jobs.run_next_job(job_id)


@shared_task(name=Task.RUN_LEASED_JOB.value, ignore_result=True)
def run_leased_job(lease: dict[str, Any]) -> None:
    """Drives the job a completion leased for the workers; the message is the lease."""
    jobs.run_leased_job(lease)


@shared_task(name=Task.SWEEP.value, ignore_result=True)
def sweep() -> dict[str, int]:
    if not jobs.sweep_is_due():
        return {"skipped": 1}  # one that piled up in the broker behind another
    return {**jobs.sweep(), "messages": sweep_sent_messages(), "timers": timers.sweep_timers()}


@shared_task(name=Task.INTERRUPT_COBOT.value, ignore_result=True)
def interrupt_cobot(interruption_id: int) -> None:
    interruptions.interrupt_cobot(interruption_id)


@shared_task(name=Task.RESUME_COBOT.value, ignore_result=True)
def resume_cobot(interruption_id: int) -> None:
    interruptions.resume_cobot(interruption_id)


@shared_task(name=Task.PURGE_MESSAGES.value, ignore_result=True)
def purge_messages() -> int:
    return purge_expired_messages()


@shared_task(name=Task.DELIVER_MESSAGE.value, ignore_result=True)
def deliver_message(message_id: int) -> None:
    """Offers a message a case sent to the other cases, once its sender's transaction committed."""
    deliver_sent_message(message_id)


@shared_task(name=Task.RING_TIMER.value, ignore_result=True)
def ring_timer(timer_id: int) -> None:
    """Fires a case's timer transition once it is due, unless it fired or was disarmed."""
    timers.ring_timer(timer_id)
